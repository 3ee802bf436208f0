"""A server's atlas in the compute pool: its chunks sized to about :data:`CHUNK_SECONDS` of
work (:func:`jik.engine.atlas_run.sized_chunks`) and run by the pool's workers
(:class:`PoolBackend`, an atlas backend of :mod:`jik.engine.atlas_backends`), first come first
served with the API's requests."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any

from ...engine.atlas_backends import IN_FLIGHT, bounded_imap
from .worker import task

#: Seconds of work in one chunk of a server's atlas (:func:`jik.engine.atlas_run.sized_chunks`):
#: the compute workers serve the API's requests between chunks, first come first served, and a
#: chunk stays far within their time limit.
CHUNK_SECONDS = 1.0


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
