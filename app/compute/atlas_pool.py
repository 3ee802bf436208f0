"""A server's atlas in the compute pool: its chunks sized to about a second of work
(:func:`sized_chunks`) and run by the pool's workers (:class:`PoolBackend`, an atlas backend of
:mod:`jik.engine.atlas_backends`), first come first served with the API's requests."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Iterator
from time import perf_counter
from typing import Any

from ...engine.atlas import AtlasPlan
from ...engine.atlas_backends import IN_FLIGHT, bounded_imap
from ...engine.atlas_run import chunk_task, run_chunk
from .worker import task

#: Seconds of work in one chunk of a server's atlas: the compute workers serve the API's requests
#: between chunks, first come first served, and a chunk stays far within their time limit.
CHUNK_SECONDS = 1.0
#: Runs timed together to size an atlas's chunks.
PROBE = 8


def sized_chunks(plan: AtlasPlan, seconds: float = CHUNK_SECONDS) -> AtlasPlan:
    """``plan`` with chunks of about ``seconds`` of work, from the time of its first runs (a
    unicycle's run costs hundreds of times a Manipulator 2's); at most the plan's own chunk.
    The first run (with its one-time costs) is timed alone: when it takes ``seconds`` or more,
    a chunk is one run and nothing more is probed (an arm's runs far out of reach take seconds
    each, and the probe is part of the request); else up to :data:`PROBE` runs, as many as fit
    in ``seconds`` at the first one's pace, are timed together. The atlas's numbers do not
    depend on its chunks."""
    start = perf_counter()
    run_chunk(chunk_task(plan, 0, 1))
    first = perf_counter() - start
    if first >= seconds:
        return dataclasses.replace(plan, chunk=1)
    n = int(min(PROBE, plan.size, max(1.0, seconds / max(first, 1e-9))))
    probe = chunk_task(plan, 0, n)
    start = perf_counter()
    run_chunk(probe)
    per_run = (perf_counter() - start) / (probe.hi - probe.lo)
    chunk = int(min(max(seconds / max(per_run, 1e-9), 1), plan.chunk))
    return dataclasses.replace(plan, chunk=chunk)


@task("starts", "fewer starts or cycles")
def atlas_chunk(fn: Callable[[Any], Any], chunk: Any) -> Any:
    """``fn(chunk)``: one chunk of an atlas in a compute worker."""
    return fn(chunk)


class PoolBackend:
    """An atlas backend (:class:`jik.engine.atlas_backends.Backend`) on the server's compute
    pool (a :class:`~jik.app.compute.pool.ComputePool`): at most ``IN_FLIGHT`` chunks per worker
    submitted at once, results in the order they finish; leaving gives up the chunks in flight."""

    def __init__(self, pool: Any) -> None:
        self.pool = pool
        self.workers = pool.settings.workers

    def __enter__(self) -> PoolBackend:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def imap_unordered(self, fn: Callable[[Any], Any], tasks: Iterable[Any]) -> Iterator[Any]:
        submit = lambda chunk: self.pool.submit(atlas_chunk, fn, chunk)  # noqa: E731
        yield from bounded_imap(submit, tasks, IN_FLIGHT * self.workers)
