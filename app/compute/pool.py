"""The compute pool: runs the request functions off the event loop, in worker processes.

:class:`ComputePool` runs them for the HTTP API, the dashboards and the API's atlases in worker
*processes* (:mod:`jik.app.compute.worker`): numpy-heavy Python loops hold the GIL, and a
computation that overruns its time limit can only be stopped by ending its process. It keeps the
queue of idle workers, replaces a worker after a death or a hang, and takes submissions from other
threads; concurrent ``/solve`` requests are micro-batched (:mod:`jik.app.compute.batching`).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import os
import pickle
import threading
from collections.abc import Callable, Iterator
from multiprocessing.reduction import ForkingPickler
from typing import Any

from .batching import SolveBatching, _Pending
from .exceptions import ComputeError, RequestError, ServiceUnavailable, WorkerLost
from .settings import Settings
from .settings import settings as environment_settings
from .worker import Worker, frame_header, work_of

#: A computation that overran its time limit while its worker computed less than this share of
#: it was not the request's work: the worker hung (the server's fault, 503).
HUNG = 0.1


class ComputePool(SolveBatching):
    """Worker processes with a bound on concurrent computations and a time limit per request.

    At most ``settings.workers`` computations run at once. A request that gets no worker within
    ``settings.timeout`` fails with :class:`ServiceUnavailable` (503, "busy"); a computation that
    runs longer than ``settings.timeout`` is stopped by killing its worker (a new one replaces it)
    and its requests fail with a :class:`RequestError` (422) naming the field that sizes the
    work. The asyncio side is rebuilt when the pool is used from another event loop (test
    clients); the processes are kept.
    """

    def __init__(self, settings: Settings | None = None) -> None:
        self.settings = settings or environment_settings()
        self._workers: list[Worker] = []
        self._lock = threading.Lock()
        self._threads = concurrent.futures.ThreadPoolExecutor(
            max_workers=self.settings.workers + 1, thread_name_prefix="jik-compute"
        )
        self._loop: asyncio.AbstractEventLoop | None = None
        self._idle: asyncio.Queue[Worker] | None = None
        self._pending: dict[str, list[_Pending]] = {}
        self._tasks: set[asyncio.Task] = set()
        self._closed = False
        #: Engine calls made and requests served by them (for tests and the benchmark).
        self.stats = {"solve_calls": 0, "solve_requests": 0, "busy": 0, "exceeded": 0}

    # -- lifecycle
    def start(self) -> None:
        """Start the worker processes (idempotent, non-blocking)."""
        with self._lock:
            self._closed = False
            while len(self._workers) < self.settings.workers:
                self._workers.append(self._new_worker())

    def _new_worker(self) -> Worker:
        return Worker(self.settings.worker_memory, self.settings.build_budget)

    def close(self) -> None:
        """Stop every worker process (none replaces them until :meth:`start`)."""
        with self._lock:
            self._closed = True
            for w in self._workers:
                w.kill()
            self._workers.clear()
            self._loop = self._idle = None

    def _bind(self) -> asyncio.Queue[Worker]:
        loop = asyncio.get_running_loop()
        if self._loop is not loop or self._idle is None:
            self.start()
            self._loop = loop
            self._idle = asyncio.Queue()
            self._pending = {}
            for w in self._workers:
                self._idle.put_nowait(w)
        return self._idle

    @property
    def _bound_loop(self) -> asyncio.AbstractEventLoop:
        """The event loop of the last :meth:`_bind` (only used after it)."""
        assert self._loop is not None, "ComputePool used before _bind()"
        return self._loop

    @property
    def _bound_idle(self) -> asyncio.Queue[Worker]:
        """The idle-worker queue of the last :meth:`_bind` (only used after it)."""
        assert self._idle is not None, "ComputePool used before _bind()"
        return self._idle

    async def warm_up(self) -> None:
        """Start the workers and wait until each has imported the engine."""
        self._bind()
        with self._lock:
            workers = list(self._workers)
        await asyncio.gather(
            *(self._bound_loop.run_in_executor(self._threads, w.wait_ready) for w in workers)
        )

    def _spawn(self, coro) -> asyncio.Task:
        task = self._bound_loop.create_task(coro)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)
        return task

    # -- core
    def _busy(self) -> ServiceUnavailable:
        self.stats["busy"] += 1
        return ServiceUnavailable(
            f"server busy: no compute slot became free within the time limit of "
            f"{self.settings.timeout:g} s ({self.settings.workers} computations run at once); "
            "retry later"
        )

    async def _acquire(self, deadline: float) -> Worker:
        if self._closed:
            raise ServiceUnavailable("the server is stopping")
        idle = self._bind()
        remaining = deadline - self._bound_loop.time()
        try:
            if remaining <= 0:
                raise TimeoutError
            return await asyncio.wait_for(idle.get(), remaining)
        except TimeoutError:
            raise self._busy() from None

    async def _dispatch(self, worker: Worker, fn: Callable, args: tuple):
        """Run one computation on ``worker``; it is killed if it overruns the time limit.

        The event loop itself waits for the worker's socket to become readable (no thread per
        computation: a thread would wait for the GIL, up to the 5 ms switch interval, while the
        loop serves other requests).
        """
        loop = self._bound_loop
        buf, sent = bytearray(), False
        try:
            if not worker.ready:  # a freshly started worker: importing the engine takes a while
                await loop.run_in_executor(self._threads, worker.wait_ready)
            deadline = loop.time() + self.settings.timeout
            cpu = worker.cpu_seconds()
            try:  # (pickled first: a task that cannot be pickled leaves the worker free)
                task = ForkingPickler.dumps((fn, args))
            except BaseException:
                self._bound_idle.put_nowait(worker)
                raise
            os.set_blocking(worker.conn.fileno(), True)  # uvloop's add_reader made it non-blocking
            worker.conn.send_bytes(task)
            sent = True
            msg = await self._reply(worker, deadline, buf)
        except TimeoutError:
            used = worker.cpu_seconds() if cpu is not None else None
            self._replace(worker)
            if cpu is not None and used is not None and used - cpu < HUNG * self.settings.timeout:
                # The worker hardly computed: it hung (stopped, deadlocked), not the request's
                # work; the server's fault.
                raise WorkerLost(
                    f"the server's compute worker stopped responding (it computed "
                    f"{used - cpu:.2f} s of the {self.settings.timeout:g} s limit) and was "
                    "replaced; retry the request"
                ) from None
            self.stats["exceeded"] += 1
            field, less = work_of(fn)
            raise RequestError(
                field,
                f"the computation exceeded the time limit of {self.settings.timeout:g} s and "
                f"was stopped; ask for less work ({less})",
            ) from None
        except (EOFError, OSError) as exc:
            self._replace(worker)
            raise WorkerLost(
                f"the server's compute worker stopped unexpectedly ({type(exc).__name__}) and "
                "was replaced"
            ) from None
        except asyncio.CancelledError:  # the request went away: collect the reply in the back
            if self._closed:  # (the server is stopping: its workers are gone)
                raise
            if sent:  # (the reply goes on from what this read of it had)
                self._spawn(self._drain(worker, loop.time() + self.settings.timeout, buf))
            elif worker.ready:
                self._bound_idle.put_nowait(worker)
            else:
                self._replace(worker)
            raise
        self._bound_idle.put_nowait(worker)
        return msg

    async def _reply(self, worker: Worker, deadline: float, buf: bytearray | None = None):
        """The worker's reply, read in the event loop as it arrives, until ``deadline``.

        The reply is framed as by :class:`multiprocessing.connection.Connection` (which the worker
        uses): a 4-byte big-endian length (-1, then 8 bytes, for huge messages), then a pickle.
        Each readiness callback reads once, so it never blocks whether or not the event loop
        (uvloop does) has made the socket non-blocking. ``buf`` holds what was read: a read cut
        short (a cancelled request) goes on from it, so the reply's rest is not taken for a new
        frame. A reply that cannot be read is an EOFError (the worker is replaced).
        """
        loop = self._bound_loop
        fd = worker.conn.fileno()
        done: asyncio.Future = loop.create_future()
        buf = bytearray() if buf is None else buf

        def take() -> None:
            size, start = frame_header(buf)
            if size is None or len(buf) < start + size or done.done():
                return
            try:
                done.set_result(pickle.loads(memoryview(buf)[start : start + size]))
            except Exception as exc:  # (a garbled reply: the worker's end is not trusted)
                done.set_exception(EOFError(f"the worker's reply could not be read: {exc!r}"))

        def readable() -> None:
            try:
                chunk = os.read(fd, 1 << 20)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                if not done.done():
                    done.set_exception(exc)
                return
            if not chunk:
                if not done.done():
                    done.set_exception(EOFError("the worker closed its connection"))
                return
            buf.extend(chunk)
            take()

        take()  # (a drained reply may be whole already)
        loop.add_reader(fd, readable)
        try:
            return await asyncio.wait_for(done, max(deadline - loop.time(), 0.0))
        finally:
            loop.remove_reader(fd)

    async def _drain(self, worker: Worker, deadline: float, buf: bytearray) -> None:
        """Wait out an abandoned computation (its reply read on from ``buf``), then give the
        worker back (or replace it)."""
        try:
            await self._reply(worker, deadline, buf)
        except (TimeoutError, EOFError, OSError):
            self._replace(worker)
        else:
            self._bound_idle.put_nowait(worker)

    def _replace(self, worker: Worker) -> None:
        worker.kill()
        with self._lock:
            if worker in self._workers:
                self._workers.remove(worker)
            if self._closed:  # (the server is stopping)
                return
            fresh = self._new_worker()
            self._workers.append(fresh)
        self._bound_idle.put_nowait(fresh)

    @staticmethod
    def _unwrap(msg):
        status, value = msg
        if status == "ok":
            return value
        if status == "request_error":
            raise RequestError(*value)
        raise ComputeError(value)

    async def run(self, fn: Callable, *args: Any) -> Any:
        """``fn(*args)`` in a worker, ``fn`` a :func:`~jik.app.compute.worker.task` (waits and
        runs within the limits). The API's tasks take the request and give the response as JSON
        bytes."""
        self._bind()
        return self._unwrap(await self._dispatch_retried(fn, args))

    async def _dispatch_retried(self, fn: Callable, args: tuple, worker: Worker | None = None):
        """:meth:`_dispatch` on ``worker`` (or the next free one); if that worker had died (it
        died while idle, or with this computation), once more on a fresh one."""
        for attempt in (1, 2):
            if worker is None:
                worker = await self._acquire(self._bound_loop.time() + self.settings.timeout)
            started = self._bound_loop.time()
            try:
                return await self._dispatch(worker, fn, args)
            except WorkerLost:
                hung = self._bound_loop.time() - started >= self.settings.timeout
                if attempt == 2 or hung:  # (a hung worker has used the request's time up)
                    raise
                worker = None
        raise AssertionError("unreachable")

    def submit(self, fn: Callable, *args: Any) -> concurrent.futures.Future:
        """:meth:`run` from another thread (the dashboards' workers): a future of its result,
        queued with the API's requests (first come, first served). Cancelling the future gives
        up the computation (its worker finishes it and is given back).

        Raises
        ------
        ServiceUnavailable
            The pool runs on no event loop (an app started without its lifespan).
        """
        loop = self._loop
        if loop is None or loop.is_closed() or not loop.is_running():
            raise ServiceUnavailable("the compute pool is not running")
        return asyncio.run_coroutine_threadsafe(self.run(fn, *args), loop)


@contextlib.contextmanager
def pool_in_thread(settings: Settings | None = None) -> Iterator[ComputePool]:
    """A started :class:`ComputePool` on an event loop of its own thread: what a server gives
    its dashboards, for code that runs outside a server (benchmarks, tests)."""
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, name="jik-pool-loop", daemon=True)
    thread.start()
    pool = ComputePool(settings)
    try:
        asyncio.run_coroutine_threadsafe(pool.warm_up(), loop).result()
        yield pool
    finally:
        pool.close()
        loop.call_soon_threadsafe(loop.stop)
        thread.join(10)
        loop.close()
