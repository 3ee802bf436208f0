"""What the latency benchmark (:mod:`jik.benchmarks.bench_latency`) measures with: a real
``jik serve`` in a process of its own (:func:`served`), the CPU seconds of a process tree read
from ``/proc`` (:func:`tree_seconds`, :class:`Machine`, :func:`quiet`: a sample is taken only
on a quiet machine), and a session's server-sent events read in a thread (:class:`EventStream`).
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

#: Seconds a change may take to reach the plots or the scene before the benchmark gives up.
CHANGE_TIMEOUT = 60.0


# -- the machine ------------------------------------------------------------------------------
_TICK = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def _proc_table() -> dict[int, tuple[int, int]]:
    """pid -> (parent pid, CPU ticks of the process and its reaped children)."""
    table = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        # (fields[0] is the state; utime, stime, cutime, cstime are fields 14-17 of stat(5))
        table[int(name)] = (int(fields[1]), sum(int(v) for v in fields[11:15]))
    return table


def tree_seconds(pid: int) -> float:
    """CPU seconds used by ``pid`` and its descendants (reaped ones included); 0 without /proc."""
    if not os.path.isdir("/proc"):
        return 0.0
    table = _proc_table()
    tree, grew = {pid}, True
    while grew:
        more = {p for p, (parent, _) in table.items() if parent in tree} - tree
        tree |= more
        grew = bool(more)
    return sum(table[p][1] for p in tree if p in table) / _TICK


def quiet(pid: int, share: float = 0.15, window: float = 0.25, timeout: float = 60.0) -> bool:
    """Wait until ``pid`` and its descendants used at most ``share`` of one core in each of two
    consecutive windows of ``window`` s; False if that did not happen within ``timeout`` s."""
    if not os.path.isdir("/proc"):
        return True
    deadline, calm = time.monotonic() + timeout, 0
    before = tree_seconds(pid)
    while time.monotonic() < deadline:
        time.sleep(window)
        now = tree_seconds(pid)
        calm = calm + 1 if now - before <= share * window else 0
        before = now
        if calm >= 2:
            return True
    return False


class Machine:
    """The machine's load over a run: load average, CPU steal, and the CPU that processes other
    than this one and its descendants (the server, the browser) used meanwhile."""

    def __init__(self) -> None:
        self.loadavg = self._loadavg()
        self._cpu = self._stat()
        self._ours = tree_seconds(os.getpid())
        self._t = time.monotonic()

    @staticmethod
    def _loadavg() -> str:
        try:
            with open("/proc/loadavg") as f:
                return " ".join(f.read().split()[:3])
        except OSError:
            return "unknown"

    @staticmethod
    def _stat() -> list[int] | None:
        try:
            with open("/proc/stat") as f:
                return [int(v) for v in f.readline().split()[1:9]]
        except (OSError, ValueError):
            return None

    def report(self) -> dict:
        cpu, wall = self._stat(), time.monotonic() - self._t
        out: dict = {
            "loadavg_start": self.loadavg,
            "loadavg_end": self._loadavg(),
            "seconds": wall,
            "cores": os.cpu_count(),
        }
        if cpu is not None and self._cpu is not None:
            d = [b - a for a, b in zip(self._cpu, cpu, strict=True)]
            busy = (d[0] + d[1] + d[2] + d[5] + d[6]) / _TICK  # user nice system irq softirq
            ours = tree_seconds(os.getpid()) - self._ours
            out["steal_percent"] = 100.0 * d[7] / max(sum(d), 1)
            out["our_cores"] = ours / wall
            out["other_cores"] = max(busy - ours, 0.0) / wall
        return out


# -- the server -------------------------------------------------------------------------------
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def served() -> Iterator[tuple[str, subprocess.Popen]]:
    """``jik serve`` (this jik) on a free loopback port: (base URL, its process)."""
    import httpx

    import jik

    port = _free_port()
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(Path(jik.__file__).resolve().parent.parent), env.get("PYTHONPATH", "")]
    ).rstrip(os.pathsep)
    log = tempfile.TemporaryFile("w+")
    proc = subprocess.Popen(
        [sys.executable, "-m", "jik", "serve", "--port", str(port)],
        env=env,
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 60
        while True:
            with contextlib.suppress(httpx.HTTPError):
                if httpx.get(f"{base}/health", timeout=2).status_code == 200:
                    break
            if proc.poll() is not None or time.monotonic() > deadline:
                log.seek(0)
                raise RuntimeError(f"jik serve did not start:\n{log.read()[-2000:]}")
            time.sleep(0.1)
        yield base, proc
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        log.close()


class EventStream:
    """A session's server-sent events, read in a thread: kind, generation, arrival, data."""

    def __init__(self, base: str, session: str) -> None:
        import httpx

        self.events: list[tuple[str, int, float, str]] = []
        self._cond = threading.Condition()
        self._client = httpx.Client(base_url=base, timeout=httpx.Timeout(10.0, read=None))
        self._thread = threading.Thread(
            target=self._read, args=(f"/api/sessions/{session}/events",), daemon=True
        )
        self._thread.start()

    def _read(self, path: str) -> None:
        kind, generation, data = "", 0, []
        try:
            with self._client.stream("GET", path) as response:
                for line in response.iter_lines():
                    if line.startswith("event: "):
                        kind = line[7:]
                    elif line.startswith("id: "):
                        generation = int(line[4:])
                    elif line.startswith("data: "):
                        data.append(line[6:])
                    elif not line and kind:
                        arrived = time.perf_counter()
                        with self._cond:
                            self.events.append((kind, generation, arrived, "\n".join(data)))
                            self._cond.notify_all()
                        kind, data = "", []
        except Exception:  # (closed by close(), or the server went away)
            return

    def wait(self, generation: int, timeout: float = CHANGE_TIMEOUT) -> tuple[float, dict]:
        """The arrival (perf_counter s) and data of the first ``result`` of ``generation`` or
        later; an ``error`` event of it raises."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for kind, g, arrived, data in self.events:
                    if g >= generation and kind == "result":
                        return arrived, json.loads(data)
                    if g >= generation and kind == "error":
                        raise RuntimeError(f"generation {g} failed: {data}")
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"no result of generation {generation} in {timeout} s")
                self._cond.wait(left)

    def close(self) -> None:
        self._client.close()
