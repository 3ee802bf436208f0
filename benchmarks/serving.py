"""A ``jik serve`` in a subprocess on a free loopback port, for the benchmarks and tests that
need a real server (its own event loop, protocol and worker processes)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import httpx


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@dataclass
class Served:
    """A running ``jik serve``: its port, base URL and process; ``log`` is filled when it has
    stopped."""

    port: int
    url: str
    process: subprocess.Popen
    log: list[str] = field(default_factory=list)


@contextmanager
def jik_serve(**env: str) -> Iterator[Served]:
    """``jik serve`` with the ``JIK_*`` settings ``env``, once /health answers (within 60 s);
    stopped with SIGTERM on leaving, its output then in ``log[0]``."""
    port = free_port()
    # Its output goes to a file, not a pipe: nobody reads a pipe while it runs, and once the
    # pipe's 64 kB were full the server's threads blocked on their next print (viser prints a
    # banner for each session's scene).
    out = tempfile.TemporaryFile("w+")
    proc = subprocess.Popen(
        [sys.executable, "-m", "jik", "serve", f"--port={port}"],
        env={**os.environ, **env},
        stdout=out,
        stderr=subprocess.STDOUT,
        text=True,
    )
    served = Served(port, f"http://127.0.0.1:{port}", proc)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                if httpx.get(f"{served.url}/health", timeout=2).status_code == 200:
                    break
            except httpx.TransportError:
                pass
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("jik serve did not start")
            time.sleep(0.1)
        yield served
    finally:
        proc.terminate()
        proc.wait(timeout=60)
        out.seek(0)
        served.log.append(out.read())
        out.close()
