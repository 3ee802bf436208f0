"""ComputePool plumbing: the event loop reads worker replies as they arrive, in any size."""

from __future__ import annotations

import asyncio
import importlib.util
import os
import pickle
import socket
import struct
import threading
from multiprocessing.connection import Connection

import numpy as np
import pytest

from jik.app.compute.pool import ComputePool
from jik.app.compute.settings import Settings
from jik.app.compute.worker import frame_header, ping, repeatability_json
from tests.helpers import run_async

LOOPS = ["asyncio"] + (["uvloop"] if importlib.util.find_spec("uvloop") else [])


def _run(coro, loop_kind: str):
    """Run ``coro`` on a fresh asyncio or uvloop event loop (uvicorn uses uvloop when present;
    its add_reader makes the socket non-blocking)."""
    if loop_kind == "uvloop":
        import uvloop

        return run_async(coro, uvloop.new_event_loop)
    return run_async(coro)


class _FakeWorker:
    """The pool's end of a socket pair; a thread plays the worker on the other end."""

    def __init__(self) -> None:
        a, b = socket.socketpair()
        self.conn = Connection(a.detach())
        self.peer = Connection(b.detach())
        self.ready = True


@pytest.mark.parametrize("loop_kind", LOOPS)
@pytest.mark.parametrize("size", [10, 70_000, 5_000_000])
def test_reply_of_any_size_is_read_whole(size, loop_kind):
    """Small (one read), medium and multi-megabyte replies (many reads) arrive intact."""
    payload = ("ok", np.arange(size, dtype=np.uint8).tobytes())
    fake = _FakeWorker()

    async def main():
        pool = ComputePool(Settings(workers=1))
        pool._loop = asyncio.get_running_loop()
        sender = threading.Thread(target=fake.peer.send, args=(payload,))
        sender.start()
        got = await pool._reply(fake, pool._loop.time() + 10)
        sender.join()
        return got

    assert _run(main(), loop_kind) == payload


@pytest.mark.parametrize("loop_kind", LOOPS)
def test_reply_from_a_dead_worker_is_eof_and_a_silent_one_times_out(loop_kind):
    async def main(close: bool):
        fake = _FakeWorker()
        pool = ComputePool(Settings(workers=1))
        pool._loop = asyncio.get_running_loop()
        if close:
            fake.peer.close()
        await pool._reply(fake, pool._loop.time() + 0.2)

    with pytest.raises(EOFError):
        _run(main(close=True), loop_kind)
    with pytest.raises(TimeoutError):
        _run(main(close=False), loop_kind)


@pytest.mark.parametrize("loop_kind", LOOPS)
def test_a_read_cut_by_a_cancel_goes_on_from_its_buffer(loop_kind):
    """A request cancelled while its reply arrives (a newer dashboard change gives up the older
    run): the drain reads on from what was read, not taking the reply's rest for a new frame
    (schemathesis saw "EOFError: Ran out of input" in the event loop and a reply never read)."""
    payload = ("ok", bytes(3_000_000))
    frame = pickle.dumps(payload)
    frame = struct.pack("!i", len(frame)) + frame
    fake = _FakeWorker()
    half = threading.Event()

    def send() -> None:
        fd = fake.peer.fileno()
        os.set_blocking(fd, True)
        os.write(fd, frame[:1000])
        half.wait(10)
        fake.peer._send(frame[1000:])  # (all of it, in as many writes as it takes)

    async def main():
        pool = ComputePool(Settings(workers=1))
        pool._loop = asyncio.get_running_loop()
        buf = bytearray()
        threading.Thread(target=send, daemon=True).start()
        task = asyncio.create_task(pool._reply(fake, pool._loop.time() + 10, buf))
        while len(buf) < 1000:
            await asyncio.sleep(0.001)
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task
        half.set()
        return await pool._reply(fake, pool._loop.time() + 10, buf)

    assert _run(main(), loop_kind) == payload


@pytest.mark.parametrize("loop_kind", LOOPS)
def test_a_garbled_reply_is_eof_not_a_reply_never_read(loop_kind):
    async def main():
        fake = _FakeWorker()
        pool = ComputePool(Settings(workers=1))
        pool._loop = asyncio.get_running_loop()
        os.write(fake.peer.fileno(), struct.pack("!i", 3) + b"xyz")
        await pool._reply(fake, pool._loop.time() + 10)

    with pytest.raises(EOFError, match="could not be read"):
        _run(main(), loop_kind)


def test_frame_headers():
    assert frame_header(bytearray(b"\x00\x00")) == (None, 0)
    assert frame_header(bytearray(struct.pack("!i", 300) + b"x")) == (300, 4)
    huge = struct.pack("!i", -1) + struct.pack("!Q", 3_000_000_000)
    assert frame_header(bytearray(huge[:8])) == (None, 0)
    assert frame_header(bytearray(huge)) == (3_000_000_000, 12)


def test_a_cancelled_request_gives_its_worker_back_after_the_reply():
    """A request cancelled mid-computation (e.g. at shutdown): the worker finishes, its reply is
    drained in the background and the same process serves the next request."""
    from jik.app.compute.schemas import RepeatabilityRequest
    from tests.app.conftest import TABLE1_PATH, X0_M2

    body = (
        RepeatabilityRequest.model_validate(
            {
                "robot": {"name": "manipulator2"},
                "algorithm": "pseudoinverse",
                "x0": X0_M2,
                "path": TABLE1_PATH,
                "cycles": 150,
            }
        )
        .model_dump_json()
        .encode()
    )

    async def main():
        pool = ComputePool(Settings(workers=1, timeout=60.0))
        try:
            await pool.warm_up()
            pid = pool._workers[0].process.pid
            task = asyncio.create_task(pool.run(repeatability_json, body))
            await asyncio.sleep(0.2)
            task.cancel()
            with pytest.raises(asyncio.CancelledError):
                await task
            assert await pool.run(ping) == "pong"
            return pid, [w.process.pid for w in pool._workers], dict(pool.stats)
        finally:
            pool.close()

    pid, pids, stats = run_async(main())
    assert pids == [pid] and stats["exceeded"] == 0


def _client(settings):
    from fastapi.testclient import TestClient

    from jik.app.api.factory import create_app

    return TestClient(create_app(settings), base_url="http://127.0.0.1")


def test_a_worker_that_died_while_idle_costs_no_request_an_error():
    """The next request is retried once on a fresh worker (it was a 503)."""
    from jik.app.compute.settings import Settings
    from tests.app.conftest import TABLE1_PATH, X0_M2, solve_body

    with _client(Settings(workers=1, timeout=60.0)) as client:
        pool = client.app.state.pool
        for path, body in [
            ("/solve", solve_body()),
            ("/repeatability", {**solve_body(), "path": TABLE1_PATH, "target": None}),
        ]:
            body = {k: v for k, v in body.items() if v is not None}
            (worker,) = pool._workers
            worker.process.kill()
            worker.process.wait(10)
            r = client.post(path, json=body)
            assert r.status_code == 200, (path, r.text)
            assert pool._workers[0] is not worker  # (replaced)
        assert X0_M2  # (the bodies start there)


def test_a_hung_worker_is_the_servers_fault_503_not_the_requests_422():
    """A worker that stops computing (SIGSTOP) runs out the time limit without using the CPU:
    503 naming the server, and a fresh worker serves the next request."""
    import os
    import signal

    from jik.app.compute.settings import Settings
    from tests.app.conftest import solve_body

    with _client(Settings(workers=1, timeout=2.0, batching=False)) as client:
        pool = client.app.state.pool
        (worker,) = pool._workers
        os.kill(worker.process.pid, signal.SIGSTOP)
        r = client.post("/solve", json=solve_body())
        assert r.status_code == 503, r.text
        assert "server's compute worker stopped responding" in r.json()["detail"]
        assert client.post("/solve", json=solve_body()).status_code == 200


def test_a_task_that_cannot_be_pickled_leaves_its_worker_free():
    """A task the pool cannot send (a deeply nested argument ran pickle out of stack) fails
    alone: its worker stays in the pool, which goes on serving (it had been lost for good, and
    with it, after as many such tasks as workers, every later request)."""
    from jik.app.dashboard.robots import check_definition

    deep: list = []
    for _ in range(5000):
        deep = [deep]
    definition = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["x1", "x2"]}
    with _client(Settings(workers=1, timeout=60.0)) as client:
        pool = client.app.state.pool
        (worker,) = pool._workers
        for _ in range(2):
            with pytest.raises(RecursionError):
                pool.submit(check_definition, {**definition, "title": deep}).result(30)
        assert pool.submit(check_definition, definition).result(30) is None
        assert pool._workers == [worker]
