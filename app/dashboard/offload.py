"""The compute processes that the sessions' dashboards share: one algorithm of a run goes there
while the session's thread computes the other (:func:`jik.app.dashboard.results.compute`).

Each dashboard has a lane (:class:`OffloadLane`); a newer change of its state cancels its
running job between legs (the lanes' newest generations are in shared memory)."""

from __future__ import annotations

import functools
import logging
import multiprocessing
import multiprocessing.connection
import os
import threading
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from jik.app.dashboard.runs import AlgorithmRun, algorithm_run

log = logging.getLogger("jik.dashboard")

# Each lane's newest generation, which the offload processes compare theirs against (set by
# _offload_init): lane k is one dashboard session's.
_newest_generation = None


def _offload_init(newest) -> None:
    global _newest_generation
    _newest_generation = newest
    # Leave with the server, however it ends (a killed server would leave this process behind).
    parent = multiprocessing.parent_process()
    if parent is not None:
        sentinel = parent.sentinel

        def watch() -> None:
            multiprocessing.connection.wait([sentinel])
            os._exit(0)

        threading.Thread(target=watch, name="jik-offload-parent", daemon=True).start()


def _offload_ready() -> bool:
    return True  # importing this module (numpy, the engine) is the warm-up


def _offload_run(lane, state, algorithm, targets, cycles, generation, resume=None) -> AlgorithmRun:
    def cancelled() -> bool:
        return _newest_generation is not None and _newest_generation[lane] > generation

    return algorithm_run(state, algorithm, targets, cycles, cancelled=cancelled, resume=resume)


#: Most lanes (dashboard sessions) one :class:`Offload` serves at once.
MAX_LANES = 1024


class Offload:
    """Processes that the dashboards share for their computation (spawned, first come first
    served).

    :func:`compute` runs the pseudoinverse here and the extended inverse in its own thread at the
    same time: on two cores a change costs the slower of the two instead of their sum. Each
    dashboard takes a :meth:`lane`; a newer change in that dashboard cancels its offloaded run
    between legs through the lane's generation counter in shared memory. If a process dies, the
    run is redone in the calling thread and the pool is started anew.

    Parameters
    ----------
    workers : int
        Processes in the pool.
    """

    def __init__(self, workers: int = 1) -> None:
        self._context = multiprocessing.get_context("spawn")  # (the server has threads: no fork)
        self._newest = self._context.Array("q", MAX_LANES, lock=False)
        self._free = list(range(MAX_LANES - 1, -1, -1))
        self._workers = workers
        self._lock = threading.Lock()
        self._pool = self._start()

    def _start(self) -> ProcessPoolExecutor:
        pool = ProcessPoolExecutor(
            max_workers=self._workers, mp_context=self._context, initializer=_offload_init,
            initargs=(self._newest,),
        )  # fmt: skip
        for _ in range(self._workers):
            pool.submit(_offload_ready)  # start and import now, not on the first change
        return pool

    def lane(self) -> OffloadLane:
        """A lane for one dashboard (:class:`OffloadLane`; close it when the dashboard stops)."""
        with self._lock:
            if not self._free:
                raise RuntimeError(f"all {MAX_LANES} lanes of the dashboards' pool are taken")
            lane = self._free.pop()
        self._newest[lane] = 0
        return OffloadLane(self, lane)

    def _release(self, lane: int) -> None:
        with self._lock:
            self._newest[lane] = 0
            self._free.append(lane)

    def _restart(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._start()

    def _submit(self, job) -> Future:
        with self._lock:
            try:
                return self._pool.submit(job)
            except (BrokenProcessPool, RuntimeError):  # died, or shut down after a death
                self._restart()
                return self._pool.submit(job)

    def _result(self, future: Future, fallback: Callable[[], AlgorithmRun]) -> AlgorithmRun:
        try:
            return future.result()
        except BrokenProcessPool:
            log.warning("a dashboard compute process died; restarting the pool")
            with self._lock:
                self._restart()
            return fallback()

    def close(self) -> None:
        with self._lock:
            self._pool.shutdown(wait=False, cancel_futures=True)


class OffloadLane:
    """One dashboard's way into an :class:`Offload`: its runs, and their cancellation."""

    def __init__(self, offload: Offload, lane: int) -> None:
        self._offload = offload
        self._lane = lane

    def newest(self, generation: int) -> None:
        """The dashboard's newest generation: its older offloaded runs stop at their next leg."""
        self._offload._newest[self._lane] = generation

    def submit(self, state, algorithm, targets, cycles, generation, resume=None) -> Future:
        """Run :func:`algorithm_run` there (``resume``: see :func:`algorithm_run`)."""
        job = functools.partial(
            _offload_run, self._lane, state, algorithm, targets, cycles, generation, resume
        )
        return self._offload._submit(job)

    def result(self, future: Future, fallback: Callable[[], AlgorithmRun]) -> AlgorithmRun:
        """The offloaded run (Cancelled and the engine's errors propagate); if the process
        died, ``fallback()`` computes it here."""
        return self._offload._result(future, fallback)

    def close(self) -> None:
        """Give the lane back (the pool goes on serving the other dashboards)."""
        self._offload._release(self._lane)
