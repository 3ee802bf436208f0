"""The dashboards' share of the server's one compute pool (:class:`jik.app.compute.pool.
ComputePool`, whose worker processes also serve the REST API, first come first served).

Each dashboard has a lane (:class:`OffloadLane`): the maps a change needs synthesized are made
there, and :func:`jik.app.dashboard.results.compute` runs one algorithm there while the
session's thread computes the others; a newer change gives up the lane's older runs. If a worker
dies, or the pool runs on no event loop, the run is computed in the calling thread. The
computations in the sessions' own threads take turns (:class:`FairSlots`).
"""

from __future__ import annotations

import collections
import concurrent.futures
import contextlib
import json
import logging
import threading
from collections.abc import Callable, Iterator
from typing import Any

from ...engine.robot_synthesis import keep_syntheses
from ..compute.exceptions import ServiceUnavailable
from ..compute.worker import task
from .analysis import synthesized_maps
from .runs import AlgorithmRun, Cancelled, algorithm_run

log = logging.getLogger("jik.dashboard")


# (max_iterations: the one control of a run's work that both tasks, a path and a target, show)
@task("max_iterations", "a lower “max … per leg”, fewer cycles or another start")
def run_offloaded(state, algorithm, targets, cycles, resume=None) -> AlgorithmRun:
    """:func:`algorithm_run` in a compute worker."""
    return algorithm_run(state, algorithm, targets, cycles, resume=resume)


class OffloadLane:
    """One dashboard's runs and map syntheses in the pool, and their cancellation."""

    def __init__(self, pool: Any) -> None:
        self._pool = pool
        self._lock = threading.Lock()
        self._running: dict[concurrent.futures.Future, int] = {}  # future -> its generation
        self._syntheses: dict[str, concurrent.futures.Future] = {}  # maps' key -> future

    def synthesize(self, state, cancelled: Callable[[], bool]) -> bool:
        """Make the E2 syntheses that ``state``'s map needs in the pool
        (:func:`~jik.app.dashboard.analysis.synthesized_maps`) and keep them in this process;
        False when the pool is not running (the caller makes them itself). ``cancelled()`` is
        polled every 0.1 s: True raises :class:`Cancelled`, the synthesis going on for the next
        change that needs the same maps.

        Raises
        ------
        RequestError
            Naming ``augmentation``: the synthesis ran out of the worker's memory or time.
        ServiceUnavailable
            No worker became free within the time limit, or the worker died.
        """
        key = json.dumps(
            [state.robot, state.robot_parameters, state.robot_definition, state.augmentation],
            sort_keys=True,
            default=str,
        )
        with self._lock:
            for other in [f for k, f in self._syntheses.items() if k != key]:
                other.cancel()
            future = self._syntheses.get(key)
            if future is None:
                try:
                    future = self._pool.submit(synthesized_maps, state)
                except ServiceUnavailable:
                    return False
                self._syntheses = {key: future}
                future.add_done_callback(lambda f: self._synthesized(key, f))
        while True:
            try:  # (kept here too: the done callback may run after this wait returns)
                keep_syntheses(future.result(timeout=0.1))
                return True
            except concurrent.futures.TimeoutError:
                if cancelled():
                    raise Cancelled from None
            except concurrent.futures.CancelledError:
                raise Cancelled from None

    def _synthesized(self, key: str, future: concurrent.futures.Future) -> None:
        """A synthesis ended: its maps are kept here, whether or not a change still waits."""
        with self._lock:
            if self._syntheses.get(key) is future:
                del self._syntheses[key]
        if not future.cancelled() and future.exception() is None:
            keep_syntheses(future.result())

    def newest(self, generation: int) -> None:
        """The dashboard's newest generation: its runs of older ones are given up."""
        with self._lock:
            stale = [f for f, g in self._running.items() if g < generation]
        for future in stale:
            future.cancel()

    def submit(
        self, state, algorithm, targets, cycles, generation, resume=None
    ) -> concurrent.futures.Future:
        """Run :func:`algorithm_run` in the pool (``resume``: see :func:`algorithm_run`)."""
        try:
            future = self._pool.submit(run_offloaded, state, algorithm, targets, cycles, resume)
        except ServiceUnavailable:
            future = concurrent.futures.Future()
            future.set_exception(ServiceUnavailable("the compute pool is not running"))
        with self._lock:
            self._running[future] = generation
        future.add_done_callback(self._forget)
        return future

    def _forget(self, future: concurrent.futures.Future) -> None:
        with self._lock:
            self._running.pop(future, None)

    def result(
        self, future: concurrent.futures.Future, fallback: Callable[[], AlgorithmRun]
    ) -> AlgorithmRun:
        """The offloaded run; :class:`Cancelled` if a newer generation gave it up; if the pool
        could not run it (a worker died, no event loop), ``fallback()`` computes it here. The
        engine's refusals and the time limit come as the pool raises them."""
        try:
            return future.result()
        except concurrent.futures.CancelledError:
            raise Cancelled from None
        except ServiceUnavailable as exc:
            log.info("a dashboard run is computed in its session's thread: %s", exc)
            return fallback()

    def close(self) -> None:
        """Give up every run still going (the dashboard stopped)."""
        with self._lock:
            running = [*self._running, *self._syntheses.values()]
        for future in running:
            future.cancel()


class FairSlots:
    """``n`` slots handed out first come, first served."""

    def __init__(self, n: int) -> None:
        if n < 1:
            raise ValueError(f"n must be >= 1, got {n}")
        self.n = n
        self._cond = threading.Condition()
        self._queue: collections.deque[object] = collections.deque()
        self._busy = 0

    @contextlib.contextmanager
    def slot(self) -> Iterator[None]:
        """Hold a slot for the block (waiting for the turn of this thread's request)."""
        me = object()
        with self._cond:
            self._queue.append(me)
            self._cond.wait_for(lambda: self._queue[0] is me and self._busy < self.n)
            self._queue.popleft()
            self._busy += 1
            self._cond.notify_all()
        try:
            yield
        finally:
            with self._cond:
                self._busy -= 1
                self._cond.notify_all()
