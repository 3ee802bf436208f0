"""Slow senders against a real ``jik serve``: a request that does not arrive whole within
``JIK_READ_SECONDS`` is cut off (408 when its headers are incomplete), however slowly its bytes
trickle in, and the server answers other clients meanwhile."""

from __future__ import annotations

import socket
import time

import httpx
import pytest

from jik.app.api.protocol import MAX_HEADER_BYTES
from jik.benchmarks.serving import jik_serve

READ_SECONDS = 1.0
HALF_SENT = 150


@pytest.fixture(scope="module")
def server():
    with jik_serve(JIK_READ_SECONDS=str(READ_SECONDS), JIK_WORKERS="1") as served:
        yield served.port, served.url
    assert "Traceback" not in served.log[0], served.log[0]


def _connect(port: int, data: bytes) -> socket.socket:
    s = socket.create_connection(("127.0.0.1", port))
    if data:
        s.sendall(data)
    return s


def _read_until_closed(s: socket.socket, timeout: float) -> bytes:
    """Everything the server sends before closing; fails if it is still open after ``timeout``."""
    s.settimeout(timeout)
    received = b""
    while chunk := s.recv(4096):
        received += chunk
    return received


def test_half_sent_requests_are_cut_off_and_others_are_served(server):
    port, base = server
    silent = [_connect(port, b"") for _ in range(10)]
    half_headers = [
        _connect(port, b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
        for _ in range(HALF_SENT)
    ]
    body = b'{"robot": {"name": "manipulator2"}, "x0": [0, 1, 0.5], "target": [1, 1]}'
    half_bodies = [
        _connect(
            port,
            b"POST /solve HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
            b"Content-Length: %d\r\n\r\n%s" % (len(body), body[:20]),
        )
        for _ in range(10)
    ]
    started = time.monotonic()
    # Meanwhile, a whole request is answered at once.
    assert httpx.get(f"{base}/health", timeout=5).status_code == 200
    try:
        for s in silent + half_headers:
            assert _read_until_closed(s, timeout=10 * READ_SECONDS).startswith(
                b"HTTP/1.1 408 Request Timeout"
            )
        for s in half_bodies:
            assert b"200 OK" not in _read_until_closed(s, timeout=10 * READ_SECONDS)
    finally:
        for s in silent + half_headers + half_bodies:
            s.close()
    assert time.monotonic() - started < 8 * READ_SECONDS


def test_trickling_bytes_do_not_extend_the_deadline(server):
    port, _ = server
    s = _connect(port, b"G")
    started = time.monotonic()
    try:
        for byte in b"ET /health HTTP/1.1\r\n":
            time.sleep(READ_SECONDS / 8)
            try:
                s.sendall(bytes([byte]))
            except OSError:
                break  # closed by the server: what this test expects
        assert _read_until_closed(s, timeout=10 * READ_SECONDS).startswith(b"HTTP/1.1 408")
    finally:
        s.close()
    assert time.monotonic() - started < 4 * READ_SECONDS


def test_a_whole_request_on_a_kept_alive_connection_is_not_cut_off(server):
    """The deadline covers reading a request, not computing it nor idling between requests."""
    _, base = server
    with httpx.Client(base_url=base, timeout=30) as client:
        for _ in range(3):
            assert client.get("/health").status_code == 200
            time.sleep(READ_SECONDS * 0.6)
        response = client.post(
            "/solve",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": "pseudoinverse",
                "x0": [0, 1, 0.5],
                "target": [1, 1.5],
            },
        )
        assert response.status_code == 200, response.text


@pytest.mark.parametrize("size", [MAX_HEADER_BYTES + 1, 32 << 20])
def test_oversized_headers_are_431_at_once_and_others_are_served(server, size):
    """Headers past the cap are refused as soon as they cross it, not read to the end (a
    32 MB header was read whole and answered 200, stalling the server meanwhile)."""
    port, base = server
    s = _connect(port, b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: ")
    started = time.monotonic()
    try:
        try:
            s.sendall(b"a" * size + b"\r\n\r\n")
        except OSError:
            pass  # closed by the server before everything was sent: what this test expects
        answer = _read_until_closed(s, timeout=5)
    finally:
        s.close()
    assert answer.startswith(b"HTTP/1.1 431 Request Header Fields Too Large"), answer[:100]
    assert answer.endswith(b"request headers larger than %d bytes\n" % MAX_HEADER_BYTES)
    assert time.monotonic() - started < 5
    assert httpx.get(f"{base}/health", timeout=5).status_code == 200


def test_headers_under_the_cap_are_served(server):
    _, base = server
    r = httpx.get(f"{base}/health", headers={"X-Big": "a" * (MAX_HEADER_BYTES // 2)}, timeout=5)
    assert r.status_code == 200, r.text


def test_a_client_that_pipelines_and_leaves_logs_nothing():
    """Requests sent back to back on one connection, which then closes: the server drops their
    answers quietly (the one being answered wrote to the closed connection and logged
    "Exception in ASGI application" with a traceback)."""
    body = b'{"robot": {"name": "manipulator2"}, "algorithm": "pseudoinverse", "x0": [0, 0, 1.5], '
    body += b'"target": [1, 1]}'
    solve = b"POST /solve HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
    solve += b"Content-Length: %d\r\n\r\n%s" % (len(body), body)
    health = b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"
    with jik_serve(JIK_WORKERS="1") as served:
        for requests in ([health] * 20, [solve] * 5, [solve, health] * 5):
            for _ in range(5):
                _connect(served.port, b"".join(requests)).close()
            time.sleep(0.5)
        assert httpx.get(f"{served.url}/health", timeout=5).status_code == 200
    log = served.log[0]
    assert "Exception in ASGI application" not in log and "Traceback" not in log, log
