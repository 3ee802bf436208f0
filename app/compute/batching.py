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
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from . import schemas as S
from .exceptions import ServiceUnavailable
from .requests import batch_key, precheck
from .worker import solve_batch

if TYPE_CHECKING:
    from .settings import Settings
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
    """The micro-batched :meth:`solve` of :class:`~jik.app.compute.pool.ComputePool` (which
    provides the members declared here)."""

    if TYPE_CHECKING:
        settings: Settings
        stats: dict[str, int]
        _pending: dict[str, list[_Pending]]

        @property
        def _bound_loop(self) -> asyncio.AbstractEventLoop: ...
        @property
        def _bound_idle(self) -> asyncio.Queue[Worker]: ...
        def _bind(self) -> asyncio.Queue[Worker]: ...
        def _busy(self) -> ServiceUnavailable: ...
        def _spawn(self, coro) -> asyncio.Task: ...
        async def _acquire(self, deadline: float) -> Worker: ...
        async def run(self, fn: Callable, *args: Any) -> Any: ...
        async def _dispatch_retried(
            self, fn: Callable, args: tuple, worker: Worker | None = None
        ): ...
        @staticmethod
        def _unwrap(msg): ...

    async def solve(self, req: S.SolveRequest) -> bytes:
        """One /solve request (JSON response bytes); micro-batched with compatible ones."""
        precheck(req)
        self._bind()
        payload = req.model_dump_json().encode()
        if not self.settings.batching:
            self.stats["solve_calls"] += 1
            self.stats["solve_requests"] += 1
            (res,) = await self.run(solve_batch, [payload])
            return self._unwrap(res)
        loop = self._bound_loop
        entry = _Pending(payload, loop.create_future(), loop.time() + self.settings.timeout)
        entry.future.add_done_callback(_retrieve)
        key = batch_key(req)
        queue = self._pending.setdefault(key, [])
        queue.append(entry)
        if len(queue) == 1:
            self._spawn(self._flush(key, first=True))
        try:
            return self._unwrap(
                await asyncio.wait_for(asyncio.shield(entry.future), entry.deadline - loop.time())
            )
        except TimeoutError:
            if entry.dispatched:  # computing: bounded by the computation's own time limit
                return self._unwrap(await entry.future)
            entry.abandoned = True
            raise self._busy() from None

    async def _flush(self, key: str, first: bool) -> None:
        if first and self.settings.batch_window > 0:
            await asyncio.sleep(self.settings.batch_window)
        queue = [p for p in self._pending.get(key, []) if not p.abandoned]
        if not queue:
            self._pending.pop(key, None)
            return
        try:
            worker = await self._acquire(max(p.deadline for p in queue))
        except ServiceUnavailable:
            for p in self._pending.pop(key, []):
                p.abandoned = True
                if not p.future.done():
                    p.future.set_exception(self._busy())
            return
        # Everything compatible that arrived while we waited for the worker joins the batch.
        queue = [p for p in self._pending.pop(key, []) if not p.abandoned]
        items, rest = queue[: self.settings.max_batch], queue[self.settings.max_batch :]
        if rest:
            self._pending[key] = rest
            self._spawn(self._flush(key, first=False))
        if not items:
            self._bound_idle.put_nowait(worker)
            return
        # A large batch is shared among the workers that are idle right now: two half batches on
        # two cores finish sooner than one whole batch on one.
        workers = [worker]
        while (
            len(items) >= (len(workers) + 1) * self.settings.min_share
            and not self._bound_idle.empty()
        ):
            workers.append(self._bound_idle.get_nowait())
        for p in items:
            p.dispatched = True
        self.stats["solve_calls"] += len(workers)
        self.stats["solve_requests"] += len(items)
        shares = np.array_split(np.arange(len(items)), len(workers))
        for w, share in zip(workers[1:], shares[1:], strict=True):
            self._spawn(self._solve_share(w, [items[i] for i in share]))
        await self._solve_share(workers[0], [items[i] for i in shares[0]])

    async def _solve_share(self, worker: Worker, items: list[_Pending]) -> None:
        """Solve ``items`` in ONE engine call on ``worker`` and hand each its result."""
        try:
            msg = await self._dispatch_retried(solve_batch, ([p.payload for p in items],), worker)
            results = self._unwrap(msg)
        except Exception as exc:  # handed to every request of the batch
            for p in items:
                if not p.future.done():
                    p.future.set_exception(exc)
            return
        for p, res in zip(items, results, strict=True):
            if not p.future.done():
                p.future.set_result(res)
