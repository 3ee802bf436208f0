"""REST load: 16 concurrent clients against POST /solve (Manipulator 2, continuous), p50 / p99.

Starts a real ``uvicorn`` server (``app.main:create_app``) on a free 127.0.0.1 port in a
subprocess, runs 16 concurrent httpx clients for 30 s (``quick``: 3 s), each posting a solve to a
random reachable target from Table 1's start, and counts every non-200 answer or transport error
as an error. It does this twice in the same run: with micro-batching (the default) and without
(``JIK_BATCH=0``: one engine call per request), and prints the ratio.

Two reference points separate the HTTP stack from the computation: the same 16 clients against
``GET /health`` (the floor set by uvicorn's h11 parser, FastAPI and the httpx clients, no
computation), and the same load on :class:`app.service.ComputePool` in-process (the batched
computation path without HTTP).
"""

from __future__ import annotations

import asyncio
import math
import os
import socket
import subprocess
import sys
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


def start_server(batching: bool, port: int | None = None) -> tuple[subprocess.Popen, str]:
    """A uvicorn server in a subprocess; returns it and its base URL once /health answers."""
    port = port or _free_port()
    env = {**os.environ, "JIK_BATCH": "1" if batching else "0"}
    cmd = [
        sys.executable, "-m", "uvicorn", "app.main:create_app", "--factory",
        "--host", "127.0.0.1", "--port", str(port), "--log-level", "warning", "--no-access-log",
    ]  # fmt: skip
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
    import dataclasses

    from app.schemas import SolveRequest
    from app.service import ComputePool, settings_from_env

    pool = ComputePool(dataclasses.replace(settings_from_env(), batching=batching))
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


def run(batching: bool, duration: float, clients: int = CLIENTS, path: str = "/solve") -> dict:
    """Start a server, load it, stop it; the statistics of the run."""
    proc, url = start_server(batching)
    try:
        return asyncio.run(_load(url, duration, clients, path))
    finally:
        stop_server(proc)


def _line(label: str, r: dict) -> str:
    return (
        f"  {label:24s} requests {r['requests']:6d}  errors {r['errors']:3d}  "
        f"{r['throughput_rps']:7.1f} req/s  p50 {r['p50_ms']:7.1f} ms  p99 {r['p99_ms']:7.1f} ms"
    )


def main(quick: bool = False) -> dict:
    duration = QUICK_DURATION if quick else DURATION
    floor = min(duration, QUICK_DURATION if quick else 10.0)
    print(
        f"{CLIENTS} concurrent httpx clients against a uvicorn server on 127.0.0.1, "
        f"{os.cpu_count()} CPUs; POST /solve = Manipulator 2, continuous pseudoinverse from "
        f"Table 1's start to random targets",
        flush=True,
    )
    results = {}
    plan = (
        ("solve_batched", "POST /solve batched", True, duration, "/solve"),
        ("solve_unbatched", "POST /solve unbatched", False, duration, "/solve"),
        ("health", "GET /health (HTTP floor)", True, floor, "/health"),
    )
    for key, label, batching, secs, path in plan:
        r = run(batching, secs, path=path)
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
    print(f"  batching, no HTTP:  {ratio(results['pool_batched'], results['pool_unbatched'])}")
    print(
        f"  target p50 < {TARGET_P50_MS:g} ms over HTTP: "
        f"{'met' if b['p50_ms'] < TARGET_P50_MS else 'NOT met'} (p50 {b['p50_ms']:.1f} ms; "
        f"GET /health floor {results['health']['p50_ms']:.1f} ms)",
        flush=True,
    )
    return results


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
