"""The worker processes: the loop a worker runs, and the server's handle on one.

A worker is a fresh interpreter that imports the engine and then answers ``(task, args)``
messages (a function registered by :func:`task`, sent by reference) with ``(status, result)``
over a :class:`~multiprocessing.connection.Connection` on a socket pair;
:class:`jik.app.compute.pool.ComputePool` sends the requests and reads the replies (framed as
:func:`frame_header` describes) on its event loop.
"""

from __future__ import annotations

import os
import socket
import struct
import subprocess
import sys
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any

import psutil

from ...engine.atlas_backends import limit_memory
from ...engine.exceptions import JikError
from . import budget
from . import schemas as S
from .exceptions import RequestError
from .requests import engine_error, repeatability_request, solve_batch_json
from .synthesis import synthesize_request


def task(field: str, less: str) -> Callable[[Callable], Callable]:
    """Make a function a task of the compute workers (``pool.run(function, *args)``), the
    request's ``field`` sizing its work and ``less`` saying how to ask for less of it. The
    function goes to the worker by reference (its module and name, as pickle sends it); a worker
    calls no other function."""

    def register(fn: Callable) -> Callable:
        fn.jik_task = (field, less)  # type: ignore[attr-defined]
        return fn

    return register


def work_of(fn: Callable) -> tuple[str, str]:
    """The field that sizes a task's work and how to ask for less (its :func:`task`)."""
    return getattr(fn, "jik_task", ("request", "less work"))


# The API's tasks take requests and give responses as JSON bytes: (de)serialization and
# validation run in the workers, in parallel, and the event loop only passes bytes along.


@task("max_iterations", "a lower max_iterations or a larger tolerance")
def solve_batch(items: list[bytes]) -> list[tuple[str, Any]]:
    """/solve requests (JSON) solved by one engine call: each one's (status, response)."""
    reqs = [S.SolveRequest.model_validate_json(b) for b in items]
    return [
        ("request_error", (r.field, r.message)) if isinstance(r, RequestError) else ("ok", r)
        for r in solve_batch_json(reqs)
    ]


@task("cycles", "fewer cycles or path points, a lower max_iterations")
def repeatability_json(body: bytes) -> bytes:
    """A /repeatability request (JSON) and its response."""
    req = S.RepeatabilityRequest.model_validate_json(body)
    return repeatability_request(req).model_dump_json().encode()


@task("region", "a smaller region, fewer nodes or qmc_nodes, a smaller grid or a lower degree")
def synthesize_json(body: bytes) -> bytes:
    """A /synthesize request (JSON) and its response."""
    req = S.SynthesizeRequest.model_validate_json(body)
    return synthesize_request(req).model_dump_json().encode()


@task("request", "less work")
def ping() -> str:
    """A worker's answer when it is up."""
    return "pong"


def _worker_entry(fd: int, memory_mb: int = 0, build_seconds: float = 0.0) -> None:
    """Entry point of a worker process started by :class:`Worker` (``python -c``): its address
    space limited to ``memory_mb`` (0: none), so that a computation too large for it raises
    MemoryError (a 422) instead of taking the machine's memory; robots built within
    ``build_seconds`` (:func:`jik.app.compute.budget.build_seconds`; 0: the environment's).
    Then its loop: say "ready", then (task, args) in, (status, result) out."""
    limit_memory(memory_mb)
    if build_seconds > 0:
        budget.BUILD_SECONDS = build_seconds
    conn = Connection(fd)
    conn.send(("ready", None))
    while True:
        try:
            fn, args = conn.recv()
        except (EOFError, OSError):
            return
        try:
            if not hasattr(fn, "jik_task"):
                raise TypeError(f"{fn!r} is not a compute task")
            msg = ("ok", fn(*args))
        except RequestError as exc:
            msg = ("request_error", (exc.field, exc.message))
        except JikError as exc:
            err = engine_error(exc)
            msg = ("request_error", (err.field, err.message))
        except MemoryError:
            field, less = work_of(fn)
            msg = ("request_error", (field, f"the computation ran out of memory; ask for {less}"))
        except Exception as exc:  # reported to the client as a 500 with its text
            msg = ("error", f"{type(exc).__name__}: {exc}")
        conn.send(msg)


#: Longest wait for a new worker to import the engine (not counted in a request's time limit).
WORKER_BOOT_TIMEOUT = 120.0


def frame_header(buf: bytearray) -> tuple[int | None, int]:
    """Payload size and offset of a :class:`~multiprocessing.connection.Connection` message
    starting in ``buf`` (size None until the header is complete)."""
    if len(buf) < 4:
        return None, 0
    (size,) = struct.unpack("!i", buf[:4])
    if size != -1:
        return size, 4
    if len(buf) < 12:
        return None, 0
    return struct.unpack("!Q", buf[4:12])[0], 12


class Worker:
    """A worker process (a fresh interpreter, so nothing of the server's state is inherited)."""

    def __init__(self, memory_mb: int = 0, build_seconds: float = 0.0) -> None:
        parent, child = socket.socketpair()
        fd = child.fileno()
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
        self.process = subprocess.Popen(
            [
                sys.executable,
                "-c",
                "from jik.app.compute.worker import _worker_entry; "
                f"_worker_entry({fd}, {int(memory_mb)}, {float(build_seconds)!r})",
            ],
            pass_fds=[fd],
            env=env,
            stdin=subprocess.DEVNULL,
        )
        child.close()
        self.conn = Connection(parent.detach())
        self.ready = False
        self._ps: psutil.Process | None = None

    def wait_ready(self) -> None:
        if not self.ready:
            if not self.conn.poll(WORKER_BOOT_TIMEOUT):
                raise OSError("worker did not start")
            self.conn.recv()
            self.ready = True

    def cpu_seconds(self) -> float | None:
        """CPU time the worker has used (user and system); None if the process is gone.

        The :class:`psutil.Process` handle is made once (making one reads the process's start
        time, which doubles the cost of the read that every dispatch does)."""
        try:
            if self._ps is None:
                self._ps = psutil.Process(self.process.pid)
            times = self._ps.cpu_times()
        except psutil.Error:
            return None
        return times.user + times.system

    def kill(self) -> None:
        self.process.kill()
        self.process.wait(5)
        self.conn.close()
