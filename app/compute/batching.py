"""Micro-batching of /solve: concurrent compatible requests solved by one engine call.

Concurrent ``/solve`` requests with the same robot, algorithm, augmentation, mode, gamma,
tolerance and iteration cap (:func:`jik.app.compute.requests.batch_key`) are micro-batched: the
first one opens a short window (``Settings.batch_window``, default 2 ms), every compatible request
arriving until a worker is free joins it, and the batch is solved by ONE engine call with x0 of
shape (n, p) and targets (n, r) (each member keeps its own adaptive step, so its result is the same
as alone). A large batch is shared among the workers idle at that moment. :class:`SolveBatching`
is the part of :class:`jik.app.compute.pool.ComputePool` that does it, on the pool's event loop,
idle workers and dispatch.
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import schemas as S
from .exceptions import ServiceUnavailable
from .precheck import precheck
from .requests import batch_key
from .worker import solve_batch

if TYPE_CHECKING:
    from .pool import ComputePool
    from .worker import Worker


def _retrieve(future: asyncio.Future) -> None:
    """Mark an abandoned request's exception as seen (no 'never retrieved' warning)."""
    if not future.cancelled():
        future.exception()


@dataclass
class _Pending:
    payload: bytes
    future: asyncio.Future
    deadline: float
    dispatched: bool = False
    abandoned: bool = False


class SolveBatching:
    """The micro-batched :meth:`solve` of a :class:`~jik.app.compute.pool.ComputePool` (on
    its event loop, settings, stats, idle workers and dispatch): the pool's ``solve``."""

    def __init__(self, pool: ComputePool) -> None:
        self.pool = pool
        #: The requests waiting for a worker, by batch key (emptied when the pool binds a loop).
        self.pending: dict[str, list[_Pending]] = {}

    async def solve(self, req: S.SolveRequest) -> bytes:
        """One /solve request (JSON response bytes); micro-batched with compatible ones."""
        precheck(req)
        self.pool._bind()
        payload = req.model_dump_json().encode()
        if not self.pool.settings.batching:
            self.pool.stats["solve_calls"] += 1
            self.pool.stats["solve_requests"] += 1
            (res,) = await self.pool.run(solve_batch, [payload])
            return self.pool._unwrap(res)
        loop = self.pool._bound_loop
        entry = _Pending(payload, loop.create_future(), loop.time() + self.pool.settings.timeout)
        entry.future.add_done_callback(_retrieve)
        key = batch_key(req)
        queue = self.pending.setdefault(key, [])
        queue.append(entry)
        if len(queue) == 1:
            self.pool._spawn(self._flush(key, first=True))
        try:
            return self.pool._unwrap(
                await asyncio.wait_for(asyncio.shield(entry.future), entry.deadline - loop.time())
            )
        except TimeoutError:
            if entry.dispatched:  # computing: bounded by the computation's own time limit
                return self.pool._unwrap(await entry.future)
            entry.abandoned = True
            raise self.pool._busy() from None

    async def _flush(self, key: str, first: bool) -> None:
        if first and self.pool.settings.batch_window > 0:
            await asyncio.sleep(self.pool.settings.batch_window)
        queue = [p for p in self.pending.get(key, []) if not p.abandoned]
        if not queue:
            self.pending.pop(key, None)
            return
        try:
            worker = await self.pool._acquire(max(p.deadline for p in queue))
        except ServiceUnavailable:
            for p in self.pending.pop(key, []):
                p.abandoned = True
                if not p.future.done():
                    p.future.set_exception(self.pool._busy())
            return
        # Everything compatible that arrived while we waited for the worker joins the batch.
        queue = [p for p in self.pending.pop(key, []) if not p.abandoned]
        items, rest = queue[: self.pool.settings.max_batch], queue[self.pool.settings.max_batch :]
        if rest:
            self.pending[key] = rest
            self.pool._spawn(self._flush(key, first=False))
        if not items:
            self.pool._bound_idle.put_nowait(worker)
            return
        # A large batch is shared among the workers that are idle right now: two half batches on
        # two cores finish sooner than one whole batch on one.
        workers = [worker]
        while (
            len(items) >= (len(workers) + 1) * self.pool.settings.min_share
            and not self.pool._bound_idle.empty()
        ):
            workers.append(self.pool._bound_idle.get_nowait())
        for p in items:
            p.dispatched = True
        self.pool.stats["solve_calls"] += len(workers)
        self.pool.stats["solve_requests"] += len(items)
        shares = np.array_split(np.arange(len(items)), len(workers))
        for w, share in zip(workers[1:], shares[1:], strict=True):
            self.pool._spawn(self._solve_share(w, [items[i] for i in share]))
        await self._solve_share(workers[0], [items[i] for i in shares[0]])

    async def _solve_share(self, worker: Worker, items: list[_Pending]) -> None:
        """Solve ``items`` in ONE engine call on ``worker`` and hand each its result."""
        try:
            msg = await self.pool._dispatch_retried(
                solve_batch, ([p.payload for p in items],), worker
            )
            results = self.pool._unwrap(msg)
        except Exception as exc:  # handed to every request of the batch
            for p in items:
                if not p.future.done():
                    p.future.set_exception(exc)
            return
        for p, res in zip(items, results, strict=True):
            if not p.future.done():
                p.future.set_result(res)
