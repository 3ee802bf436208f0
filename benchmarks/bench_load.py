"""REST load: 16 concurrent clients against POST /solve (Manipulator 2, continuous), p50 / p99.

Starts a real ``uvicorn`` server (``jik.app.api.factory:create_app``, from wherever jik is
installed) on a free 127.0.0.1 port in a subprocess, runs 16 concurrent httpx clients for 30 s
(``quick``: 3 s), each posting a solve to a random reachable target from Table 1's start, and counts
every non-200 answer or transport error as an error. It does this three times in the same run: with
micro-batching and the /solve fast path (the defaults), without batching (``JIK_BATCH=0``: one
engine call per request), and with FastAPI's route alone (``JIK_FAST_SOLVE=0``, see
:mod:`jik.app.api.fastpath`), and prints the ratios.

The load generator matters on a 2-core machine: 16 Python (httpx) clients take much of the CPU
the server needs. When Debian's ``wrk`` (C, one thread, 16 connections) is installed, it is the
load generator of record: it checks every response for ``"converged":true`` in a Lua hook and
reports p50/p99 from its own latency histogram. The httpx clients run too, as a reference.

Two reference points separate the HTTP stack from the computation: the same 16 clients against
``GET /health`` (the HTTP floor, no computation), and the same load on
:class:`jik.app.compute.pool.ComputePool` in-process (the batched computation path without HTTP).
"""

from __future__ import annotations

import asyncio
import math
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time

import httpx
import numpy as np

CLIENTS = 16
DURATION = 30.0
QUICK_DURATION = 3.0
#: The issue's target for the batched continuous Manipulator 2 solve.
TARGET_P50_MS = 15.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(
    batching: bool, port: int | None = None, fast: bool = True
) -> tuple[subprocess.Popen, str]:
    """A uvicorn server in a subprocess; returns it and its base URL once /health answers.

    ``fast=False`` serves /solve by the FastAPI route only (``JIK_FAST_SOLVE=0``).
    """
    port = port or _free_port()
    env = {**os.environ, "JIK_BATCH": "1" if batching else "0", "JIK_FAST_SOLVE": str(int(fast))}
    cmd = [
        sys.executable,
        "-m",
        "uvicorn",
        "jik.app.api.factory:create_app",
        "--factory",
        "--host",
        "127.0.0.1",
        "--port",
        str(port),
        "--log-level",
        "warning",
        "--no-access-log",
    ]
    proc = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"server exited with code {proc.returncode}")
        try:
            if httpx.get(f"{url}/health", timeout=1).status_code == 200:
                return proc, url
        except httpx.HTTPError:
            pass
        time.sleep(0.2)
    proc.kill()
    raise RuntimeError("server did not answer /health within 120 s")


def stop_server(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.wait(15)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(5)


def _bodies(n: int, seed: int = 0) -> list[dict]:
    """Solve requests from Table 1's start to random targets inside the reachable band."""
    rng = np.random.default_rng(seed)
    t = rng.uniform([0.0, 0.5], [1.5, 2.0], size=(n, 2))
    return [
        {
            "robot": {"name": "manipulator2", "l": 1.0},
            "algorithm": "pseudoinverse",
            "x0": [0.0, 0.0, math.pi / 2],
            "target": [float(a), float(b)],
        }
        for a, b in t
    ]


async def _client(
    url: str, start: asyncio.Event, duration: float, bodies: list[dict], path: str, out: dict
):
    """One client: open its connection and warm up, wait for the start, then load."""
    async with httpx.AsyncClient(base_url=url, timeout=60) as client:
        for body in bodies[:2]:
            (await client.post("/solve", json=body)).raise_for_status()
        out["ready"] += 1
        await start.wait()
        stop = out["t0"] + duration
        i = 0
        while time.perf_counter() < stop:
            body = bodies[i % len(bodies)]
            i += 1
            t0 = time.perf_counter()
            try:
                if path == "/health":
                    r = await client.get(path)
                else:
                    r = await client.post(path, json=body)
            except httpx.HTTPError as exc:
                out["errors"].append(repr(exc))
                continue
            dt = time.perf_counter() - t0
            if r.status_code != 200 or (path == "/solve" and not r.json().get("converged")):
                out["errors"].append(f"{r.status_code}: {r.text[:200]}")
            else:
                out["latency"].append(dt)


def _summary(lat: list[float], errs: list[str], wall: float) -> dict:
    ms = np.array(lat) * 1e3
    return {
        "requests": len(lat),
        "errors": len(errs),
        "first_errors": errs[:3],
        "throughput_rps": len(lat) / wall,
        "p50_ms": float(np.percentile(ms, 50)) if len(ms) else math.nan,
        "p99_ms": float(np.percentile(ms, 99)) if len(ms) else math.nan,
    }


async def _load(url: str, duration: float, clients: int, path: str = "/solve") -> dict:
    """``clients`` concurrent clients, all connected and warmed up before the clock starts."""
    start = asyncio.Event()
    out: dict = {"ready": 0, "t0": 0.0, "latency": [], "errors": []}
    tasks = [
        asyncio.create_task(_client(url, start, duration, _bodies(64, seed=k), path, out))
        for k in range(clients)
    ]
    while out["ready"] < clients:
        await asyncio.sleep(0.01)
    out["t0"] = time.perf_counter()
    start.set()
    await asyncio.gather(*tasks)
    return _summary(out["latency"], out["errors"], time.perf_counter() - out["t0"])


async def _pool_load(duration: float, clients: int, batching: bool) -> dict:
    """The same load on the compute pool in-process: the computation path without HTTP."""
    from ..app.compute.pool import ComputePool
    from ..app.compute.schemas import SolveRequest
    from ..app.compute.settings import settings

    pool = ComputePool(settings().model_copy(update={"batching": batching}))
    try:
        await pool.warm_up()
        lat: list[float] = []
        errs: list[str] = []

        async def client(k: int, stop: float) -> None:
            reqs = [SolveRequest.model_validate(b) for b in _bodies(64, seed=k)]
            i = 0
            while time.perf_counter() < stop:
                t0 = time.perf_counter()
                try:
                    await pool.solve(reqs[i % len(reqs)])
                    lat.append(time.perf_counter() - t0)
                except Exception as exc:  # counted, not raised: the run goes on
                    errs.append(repr(exc))
                i += 1

        t0 = time.perf_counter()
        await asyncio.gather(*(client(k, t0 + duration) for k in range(clients)))
        out = _summary(lat, errs, time.perf_counter() - t0)
        out["mean_batch"] = pool.stats["solve_requests"] / max(pool.stats["solve_calls"], 1)
        return out
    finally:
        pool.close()


def run(
    batching: bool, duration: float, clients: int = CLIENTS, path: str = "/solve", fast: bool = True
) -> dict:
    """Start a server, load it, stop it; the statistics of the run."""
    proc, url = start_server(batching, fast=fast)
    try:
        return asyncio.run(_load(url, duration, clients, path))
    finally:
        stop_server(proc)


#: wrk script: random reachable targets as in ``_bodies``, every answer checked for convergence.
WRK_SCRIPT = """
local threads = {}
function setup(thread) table.insert(threads, thread) end
function init(args) failed = 0; math.randomseed(os.time() + math.floor(os.clock() * 1e6)) end
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
request = function()
  local body = string.format('{"robot": {"name": "manipulator2", "l": 1.0}, '
    .. '"algorithm": "pseudoinverse", "x0": [0, 0, 1.5707963267948966], '
    .. '"target": [%.6f, %.6f]}', 1.5 * math.random(), 0.5 + 1.5 * math.random())
  return wrk.format(nil, "/solve", nil, body)
end
function response(status, headers, body)
  if status ~= 200 or not string.find(body, '"converged":true', 1, true) then
    failed = failed + 1
  end
end
function done(summary, latency, requests)
  local f = 0
  for _, t in ipairs(threads) do f = f + t:get("failed") end
  local e = summary.errors
  io.write(string.format("JIK requests=%d failed=%d socket=%d p50=%f p99=%f seconds=%f\\n",
    summary.requests, f, e.connect + e.read + e.write + e.timeout,
    latency:percentile(50) / 1000, latency:percentile(99) / 1000, summary.duration / 1e6))
end
"""


def run_wrk(
    batching: bool, duration: float, clients: int = CLIENTS, path: str = "/solve", fast: bool = True
) -> dict:
    """The same load generated by ``wrk`` (one C thread, ``clients`` connections)."""
    proc, url = start_server(batching, fast=fast)
    try:
        with tempfile.NamedTemporaryFile("w", suffix=".lua", delete=False) as f:
            f.write(
                WRK_SCRIPT
                if path == "/solve"
                else WRK_SCRIPT.split("wrk.method")[0]
                + "function response(status, headers, body)\n"
                + "  if status ~= 200 then failed = failed + 1 end\nend\n"
                + "function done"
                + WRK_SCRIPT.split("function done")[1]
            )
        target = url if path == "/solve" else url + path
        cmd = ["wrk", "-t1", f"-c{clients}", f"-d{duration:g}s", "-s", f.name, target]
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=duration + 60).stdout
    finally:
        stop_server(proc)
        os.unlink(f.name)
    m = re.search(
        r"JIK requests=(\d+) failed=(\d+) socket=(\d+) p50=([\d.]+) p99=([\d.]+) "
        r"seconds=([\d.]+)",
        out,
    )
    if m is None:
        raise RuntimeError(f"could not read wrk's output: {out[-500:]}")
    n, failed, sock, p50, p99, secs = (float(g) for g in m.groups())
    return {
        "requests": int(n),
        "errors": int(failed + sock),
        "first_errors": [],
        "throughput_rps": n / secs,
        "p50_ms": p50,
        "p99_ms": p99,
    }


def _line(label: str, r: dict) -> str:
    return (
        f"  {label:38s} requests {r['requests']:6d}  errors {r['errors']:3d}  "
        f"{r['throughput_rps']:7.1f} req/s  p50 {r['p50_ms']:7.1f} ms  p99 {r['p99_ms']:7.1f} ms"
    )


def main(quick: bool = False) -> dict:
    duration = QUICK_DURATION if quick else DURATION
    floor = min(duration, QUICK_DURATION if quick else 10.0)
    wrk = shutil.which("wrk") is not None
    print(
        f"{CLIENTS} concurrent clients ({'wrk, and httpx as a reference' if wrk else 'httpx'}) "
        f"against a uvicorn server on 127.0.0.1, {os.cpu_count()} CPUs; POST /solve = "
        "Manipulator 2, continuous pseudoinverse from Table 1's start to random targets",
        flush=True,
    )
    if not wrk:
        print(
            "  (install wrk, e.g. apt-get install wrk, for a load generator that does not "
            "compete with the server for the CPU)"
        )
    results = {}
    runner = run_wrk if wrk else run
    tag = "wrk" if wrk else "httpx"
    plan = [
        ("solve_batched", f"POST /solve batched ({tag})", runner, True, True, duration, "/solve"),
        (
            "solve_unbatched",
            f"POST /solve unbatched ({tag})",
            runner,
            False,
            True,
            duration,
            "/solve",
        ),
        (
            "solve_route",
            f"POST /solve batched, route only ({tag})",
            runner,
            True,
            False,
            duration,
            "/solve",
        ),
        ("health", f"GET /health floor ({tag})", runner, True, True, floor, "/health"),
    ]
    if wrk:
        plan.append(
            ("httpx_batched", "POST /solve batched (httpx)", run, True, True, floor, "/solve")
        )
    for key, label, fn, batching, fast, secs, path in plan:
        r = fn(batching, secs, path=path, fast=fast)
        results[key] = r
        print(_line(f"{label} {secs:g} s", r), flush=True)
        for e in r["first_errors"]:
            print(f"    error: {e}")
    for key, batching in (("pool_batched", True), ("pool_unbatched", False)):
        r = asyncio.run(_pool_load(floor, CLIENTS, batching))
        results[key] = r
        label = f"pool {'batched' if batching else 'unbatched'}, no HTTP {floor:g} s"
        print(_line(label, r) + f"  mean batch {r['mean_batch']:.1f}", flush=True)

    def ratio(b: dict, u: dict) -> str:
        return (
            f"p50 {u['p50_ms'] / b['p50_ms']:.1f}x lower, "
            f"throughput {b['throughput_rps'] / u['throughput_rps']:.1f}x higher"
        )

    b = results["solve_batched"]
    print(f"  batching over HTTP: {ratio(b, results['solve_unbatched'])}")
    print(f"  fast path vs FastAPI route only: {ratio(b, results['solve_route'])}")
    print(f"  batching, no HTTP:  {ratio(results['pool_batched'], results['pool_unbatched'])}")
    print(
        f"  target p50 < {TARGET_P50_MS:g} ms over HTTP ({tag}): "
        f"{'met' if b['p50_ms'] < TARGET_P50_MS else 'NOT met'} (p50 {b['p50_ms']:.1f} ms; "
        f"GET /health floor {results['health']['p50_ms']:.1f} ms)",
        flush=True,
    )
    return results


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
