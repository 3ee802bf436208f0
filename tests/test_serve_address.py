"""`jik serve`'s address: bad ``--host`` and ``--port`` get one line naming the option (no
traceback, nothing started), and the dashboard's address is printed once the server answers."""

from __future__ import annotations

import os
import select
import socket
import subprocess
import sys
import urllib.request

import pytest

from jik.cli import main
from jik.cli.serve_address import dashboard_url

pytest.importorskip("uvicorn", reason="jik serve needs the app extra")


@pytest.mark.parametrize(
    ("argv", "text"),
    [
        (["--port", "99999"], "argument --port: 99999 is not a port (1 to 65535)"),
        (["--port", "0"], "argument --port: 0 is not a port (1 to 65535)"),
        (["--port", "http"], "argument --port: 'http' is not a port number"),
    ],
)
def test_a_port_out_of_range_is_refused_by_the_parser(capsys, argv, text):
    with pytest.raises(SystemExit) as exited:
        main(["serve", *argv])
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert text in err and "Traceback" not in err, err


@pytest.mark.parametrize(
    ("host", "text"),
    [
        # TEST-NET-3 (RFC 5737): never an address of this machine.
        ("203.0.113.5", "--host 203.0.113.5: cannot listen there"),
        # .invalid never resolves (RFC 2606).
        ("nosuch.invalid", "--host nosuch.invalid: not an address or a host name that resolves"),
    ],
)
def test_a_host_that_is_not_this_machines_is_one_line(capsys, monkeypatch, host, text):
    """Refused before the server is built: run_server is never called."""
    from jik.app.api import server

    def started(**kwargs):
        raise AssertionError("the server was started")

    monkeypatch.setattr(server, "run_server", started)
    assert main(["serve", "--host", host]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"jik serve: {text}") and err.count("\n") == 1, err


def test_a_taken_port_is_named_before_anything_starts(capsys, monkeypatch):
    from jik.app.api import server

    monkeypatch.setattr(server, "run_server", lambda **kw: pytest.fail("the server started"))
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["serve", "--port", str(port)]) == 2
    err = capsys.readouterr().err
    assert f"port {port} on 127.0.0.1 is in use" in err and "--port PORT" in err, err


def test_the_address_to_open():
    assert dashboard_url("127.0.0.1", 8000) == "http://127.0.0.1:8000/"
    assert dashboard_url("0.0.0.0", 8000) == "http://127.0.0.1:8000/"
    assert dashboard_url("::", 8080) == "http://[::1]:8080/"
    assert dashboard_url("::1", 8080) == "http://[::1]:8080/"
    assert dashboard_url("localhost", 80) == "http://localhost:80/"


def test_serve_prints_the_dashboards_address_once_it_answers(tmp_path):
    """The line comes once the server answers: the page is there when it is read."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "jik", "serve", "--port", str(port)],
        cwd=tmp_path,
        env={**os.environ, "JIK_WORKERS": "1"},
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert server.stdout is not None
        ready, _, _ = select.select([server.stdout], [], [], 120)
        assert ready, "jik serve printed nothing in 120 s"
        line = server.stdout.readline()
        url = f"http://127.0.0.1:{port}/"
        assert line == f"jik serve: the dashboard is at {url} (API docs: {url}docs)\n", line
        with urllib.request.urlopen(url, timeout=60) as page:
            assert page.status == 200 and "<html" in page.read().decode().lower()
    finally:
        server.terminate()
        server.communicate(timeout=60)
    assert server.returncode == 0
