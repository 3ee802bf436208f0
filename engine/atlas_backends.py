"""Where an atlas's chunks run: here, in a local process pool, or on a Dask cluster.

One option picks the backend (:func:`backend_for`): ``None`` or ``"inprocess"``, ``"processes:N"``
(``concurrent.futures`` with N worker processes), ``"dask:ADDRESS"`` (the scheduler of a running
``dask.distributed`` cluster, whose workers have jik installed) or ``"dask:local:N"`` (a
``LocalCluster`` of N single-threaded worker processes, to try it on one machine). Dask is
imported only when a Dask backend is entered: the engine does not depend on it (``pip install
'jik-lab[atlas]'`` installs it).

Every backend keeps a bounded number of chunks in flight (:data:`IN_FLIGHT` per worker), takes
the next task from the caller's iterator only when one finishes, and yields results in the order
they finish, so the memory of a sweep is that of a few chunks whatever its size.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any, Protocol

from jik import install_hint

from .exceptions import InvalidInputError

#: Chunks in flight per worker: one running, one queued so a worker never waits for the caller.
IN_FLIGHT = 2
#: Most local worker processes.
MAX_WORKERS = 256
#: glibc malloc settings of a LocalCluster's workers. Dask's nanny sets MALLOC_TRIM_THRESHOLD_ to
#: 64 kB, which also turns off glibc's adaptive mmap threshold: every array over 128 kB of the
#: batched solver is then mapped and unmapped, page by page (1.8x the CPU time of a chunk, 3.6x
#: the page faults). Arrays up to 16 MB come from the heap instead, returned to the system past
#: 64 MB (a chunk's working set is a few MB). Workers of a remote cluster get their owner's.
WORKER_ENVIRONMENT = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 64 << 20,
    "distributed.nanny.pre-spawn-environ.MALLOC_MMAP_THRESHOLD_": 16 << 20,
}


def bounded_imap(submit: Callable[[Any], Future], tasks: Iterable[Any], limit: int) -> Iterator:
    """Results of ``submit(task)`` for each task as they finish, with at most ``limit`` futures
    in flight (the tasks are generated lazily, so a large atlas's chunks never all exist at once);
    the futures still pending when the caller stops are cancelled."""
    pending: set[Future] = set()
    try:
        for task in tasks:
            pending.add(submit(task))
            if len(pending) >= limit:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                yield from (f.result() for f in finished)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            yield from (f.result() for f in finished)
    finally:
        for f in pending:
            f.cancel()


class Backend(Protocol):
    """Runs ``fn`` on tasks, a bounded number at a time, yielding results as they finish."""

    workers: int

    def __enter__(self) -> Backend: ...

    def __exit__(self, *exc: object) -> None: ...

    def imap_unordered(self, fn: Callable[[Any], Any], tasks: Iterable[Any]) -> Iterator[Any]: ...


class InProcess:
    """Chunks one after another in this process (the default)."""

    workers = 1

    def __enter__(self) -> InProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def imap_unordered(self, fn, tasks):
        return map(fn, tasks)


def limit_memory(memory_mb: int) -> None:
    """Limit this process's address space to ``memory_mb`` (0: no limit), so that a chunk too
    large for it raises MemoryError instead of taking the machine's memory."""
    if memory_mb <= 0:
        return
    try:
        import resource

        limit = memory_mb * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (ImportError, ValueError, OSError):  # (no such limit here: run without)
        pass


class ProcessPool:
    """A local pool of ``workers`` processes (``concurrent.futures``, spawned: safe to start
    from a threaded program such as the server), each within ``memory_mb`` (0: no limit)."""

    def __init__(self, workers: int, memory_mb: int = 0) -> None:
        self.workers = workers
        self.memory_mb = memory_mb
        self._pool: ProcessPoolExecutor | None = None

    def __enter__(self) -> ProcessPool:
        context = multiprocessing.get_context("spawn")
        self._pool = ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=context,
            initializer=limit_memory,
            initargs=(self.memory_mb,),
        )
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def imap_unordered(self, fn, tasks):
        assert self._pool is not None, "enter the backend first"
        pool = self._pool
        yield from bounded_imap(lambda task: pool.submit(fn, task), tasks, IN_FLIGHT * self.workers)


class Dask:
    """A ``dask.distributed`` cluster: a scheduler ``address``, or ``local:N`` for a
    ``LocalCluster`` of N single-threaded worker processes made (and closed) here."""

    def __init__(self, address: str) -> None:
        self.address = address
        self.local = _local_workers(address)
        self.workers = self.local or 1
        self._client: Any = None
        self._cluster: Any = None
        self._as_completed: Any = None

    def __enter__(self) -> Dask:
        try:
            import dask
            from dask.distributed import Client, LocalCluster, as_completed
        except ImportError as error:
            raise InvalidInputError(
                f"a Dask backend needs dask.distributed ({error}); {install_hint('atlas')}",
                field="backend",
            ) from error
        self._as_completed = as_completed
        if self.local:
            with dask.config.set(WORKER_ENVIRONMENT):
                self._cluster = LocalCluster(
                    n_workers=self.local,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                )
            self._client = Client(self._cluster)
        else:
            try:
                self._client = Client(self.address)
            except ValueError as error:  # (OSError: a scheduler out of reach, said as it is)
                raise InvalidInputError(
                    f"a Dask scheduler's address is 'HOST:PORT' or 'tcp://HOST:PORT' (or "
                    f"'local:N'), got {self.address!r}: {error}",
                    field="backend",
                ) from error
            self.workers = max(1, len(self._client.scheduler_info().get("workers", {})))
        return self

    def __exit__(self, *exc: object) -> None:
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        self._client = self._cluster = None

    def imap_unordered(self, fn, tasks):
        assert self._client is not None, "enter the backend first"
        client = self._client
        tasks = iter(tasks)
        queue = self._as_completed()
        live = []
        try:
            for task in tasks:
                live.append(client.submit(fn, task, pure=False))
                queue.add(live[-1])
                if len(live) >= IN_FLIGHT * self.workers:
                    break
            for future in queue:
                live.remove(future)
                yield future.result()
                future.release()
                task = next(tasks, None)
                if task is not None:
                    live.append(client.submit(fn, task, pure=False))
                    queue.add(live[-1])
        finally:
            for future in live:
                future.cancel()


def _local_workers(address: str) -> int:
    """N of "local:N", 0 for a scheduler address."""
    if not address.startswith("local"):
        return 0
    _, _, n = address.partition(":")
    if not n.isdigit() or not 1 <= int(n) <= MAX_WORKERS:
        raise InvalidInputError(
            f"a local Dask cluster is 'local:N' with 1 <= N <= {MAX_WORKERS}, got {address!r}",
            field="backend",
        )
    return int(n)


def backend_for(option: str | Backend | None) -> Backend:
    """The backend an option names: None or "inprocess", "processes:N", "dask:ADDRESS",
    "dask:local:N"; a Backend object is used as it is."""
    if option is None or option == "inprocess":
        return InProcess()
    if not isinstance(option, str):
        if all(hasattr(option, a) for a in ("__enter__", "__exit__", "imap_unordered")):
            return option
        raise InvalidInputError(
            "backend must be 'inprocess', 'processes:N', 'dask:ADDRESS', 'dask:local:N' or a "
            f"Backend (a context manager with imap_unordered), got {type(option).__name__}",
            field="backend",
        )
    kind, _, rest = option.partition(":")
    if kind == "processes":
        if not rest.isdigit() or not 1 <= int(rest) <= MAX_WORKERS:
            raise InvalidInputError(
                f"a process pool is 'processes:N' with 1 <= N <= {MAX_WORKERS}, got {option!r}",
                field="backend",
            )
        return ProcessPool(int(rest))
    if kind == "dask" and rest:
        return Dask(rest)
    raise InvalidInputError(
        f"backend must be 'inprocess', 'processes:N', 'dask:ADDRESS' or 'dask:local:N', got "
        f"{option!r}",
        field="backend",
    )
