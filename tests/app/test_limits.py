"""Heavy work runs off the event loop, with a bound on concurrency and a time limit (503)."""

from __future__ import annotations

import asyncio
import time

import httpx

from jik.app.api.factory import create_app
from jik.app.compute.settings import Settings
from tests.app.conftest import TABLE1_PATH, X0_M2, solve_body
from tests.helpers import run_async

HEAVY = {
    "robot": {"name": "manipulator2"},
    "algorithm": "pseudoinverse",
    "x0": X0_M2,
    "path": TABLE1_PATH,
    "cycles": 1000,  # ~4000 solves: far beyond a 1.5 s limit
}


def _client(app) -> httpx.AsyncClient:
    transport = httpx.ASGITransport(app=app)
    return httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1", timeout=60)


async def _overrun(app):
    async with _client(app) as c:
        await app.state.pool.warm_up()
        heavy = asyncio.create_task(c.post("/repeatability", json=HEAVY))
        await asyncio.sleep(0.2)
        queued = asyncio.create_task(c.post("/solve", json=solve_body()))
        health = []
        while not heavy.done():
            t = time.perf_counter()
            r = await c.get("/health")
            health.append((r.status_code, time.perf_counter() - t))
            await asyncio.sleep(0.05)
        return await heavy, await queued, health


def test_overrun_is_stopped_and_health_stays_responsive():
    """A 1000-cycle run overruns its 1.5 s limit: 422 naming cycles, its worker is killed and
    replaced, and the solve queued behind it is then served. /health answers quickly meanwhile."""
    app = create_app(Settings(workers=1, timeout=1.5))
    try:
        heavy, queued, health = run_async(_overrun(app))
        stats = app.state.pool.stats
    finally:
        app.state.pool.close()
    assert heavy.status_code == 422
    (err,) = heavy.json()["detail"]
    assert err["loc"] == ["body", "cycles"]
    assert err["msg"].startswith("cycles: the computation exceeded the time limit of 1.5 s and")
    assert "fewer cycles or path points" in err["msg"]
    assert stats["exceeded"] == 1
    assert queued.status_code == 200 and queued.json()["converged"]
    assert len(health) >= 5
    assert all(code == 200 for code, _ in health)
    assert max(dt for _, dt in health) < 0.5


async def _held(app):
    async with _client(app) as c:
        pool = app.state.pool
        await pool.warm_up()
        worker = await pool._acquire(pool._loop.time() + 5)  # every slot taken
        try:
            solve = asyncio.create_task(c.post("/solve", json=solve_body()))
            rep = asyncio.create_task(c.post("/repeatability", json={**HEAVY, "cycles": 1}))
            health = await c.get("/health")
            return await solve, await rep, health
        finally:
            pool._idle.put_nowait(worker)


def test_no_free_slot_is_busy_503():
    """Every worker busy for longer than the limit: 503 'server busy' for each request kind."""
    app = create_app(Settings(workers=1, timeout=0.5))
    try:
        solve, rep, health = run_async(_held(app))
    finally:
        app.state.pool.close()
    assert health.status_code == 200
    for r in (solve, rep):
        assert r.status_code == 503
        assert r.json()["detail"].startswith("server busy: no compute slot became free within")
        assert r.headers["retry-after"] == "1"


def test_a_computation_over_the_worker_memory_limit_is_422_and_the_worker_lives_on():
    """Each worker's address space is limited (Settings.worker_memory, JIK_WORKER_MEMORY_MB):
    a heavy request (unicycle, 24 nodes, a 61-point grid over a wide three-variable box) ends in
    a 422 that says what to ask for less of, here under a small limit so that it fails at once
    (400 MB: the worker's address space after its imports is about 340 MB, so the request's own
    parsing still has room and the computation is what runs out)."""
    from fastapi.testclient import TestClient

    from jik.app.api.factory import create_app

    settings = Settings(workers=1, timeout=60.0, worker_memory=400)
    with TestClient(create_app(settings), base_url="http://127.0.0.1") as client:
        (worker,) = client.app.state.pool._workers
        with open(f"/proc/{worker.process.pid}/limits") as f:
            (line,) = [row for row in f if row.startswith("Max address space")]
        assert line.split()[3] == str(400 * 1024 * 1024)
        wide = {"lambda10": [-3, 3], "lambda11": [-3, 3], "lambda20": [-3, 3]}
        body = {
            "robot": {"name": "unicycle"},
            "method": "evaluate",
            "grid": 61,
            "nodes": 24,
            "region": wide,
        }
        r = client.post("/synthesize", json=body)
        assert r.status_code == 422, r.text
        (error,) = r.json()["detail"]
        assert error["loc"] == ["body", "region"] and "ran out of memory" in error["msg"]
        assert "a smaller region, fewer nodes or qmc_nodes, a smaller grid" in error["msg"]
        assert client.app.state.pool._workers[0] is worker  # (not killed)
        assert client.get("/robots").status_code == 200
        # A map synthesized for a solve that runs out: the augmentation's fault, not the run's
        # (max_iterations, the solve's own measure of work).
        box = {name: [0.1, 0.9] for name in ("x1", "x2", "x3")}
        solve = {
            "robot": {
                "name": "formula",
                "variables": ["x1", "x2", "x3", "x4"],
                "task": ["x1 + x2*x3", "x2 + x4*x1", "x3*x1 + x4"],
            },
            "algorithm": "extended",
            "augmentation": {"name": "e2_synthesized", "region": box, "degree": 16},
            "x0": [0.5] * 4,
            "target": [0.8] * 3,
        }
        r = client.post("/solve", json=solve)
        assert r.status_code == 422, r.text
        (error,) = r.json()["detail"]
        assert error["loc"] == ["body", "augmentation"], error
        assert "ran out of memory; ask for a lower degree or a smaller region" in error["msg"]


#: An atlas that runs for about a minute of one core (cancelled long before).
LONG_ATLAS = {"robot": {"name": "manipulator2"}, "path": TABLE1_PATH, "starts": 20000, "cycles": 5}
SHORT_ATLAS = {**LONG_ATLAS, "starts": 4, "cycles": 1, "arc": [-1.0, 1.0]}


def test_a_queued_atlas_says_what_it_waits_for():
    """One atlas computes at a time: the others say how many jobs are before them, and start in
    the order they came (the queue's wait was invisible in the job's status)."""
    from fastapi.testclient import TestClient

    from jik.app.compute.atlas_jobs import AtlasJobs
    from jik.app.compute.atlas_plan import AtlasLimits

    app = create_app(Settings(workers=1, timeout=60.0))
    app.state.atlas_jobs = AtlasJobs(AtlasLimits(max_jobs=4, per_client=3), app.state.pool)
    with TestClient(app) as client:
        ids = [client.post("/atlas", json=LONG_ATLAS).json()["id"]]
        ids += [client.post("/atlas", json=SHORT_ATLAS).json()["id"] for _ in range(2)]
        try:
            deadline = time.monotonic() + 30
            while client.get(f"/atlas/{ids[0]}").json()["status"] != "running":
                assert time.monotonic() < deadline
                time.sleep(0.1)
            second, third = (client.get(f"/atlas/{i}").json() for i in ids[1:])
            assert (second["status"], second["queue_position"]) == ("queued", 1)
            says = "queued behind 1 atlas job (1 computing, the rest waiting); it starts when"
            assert second["message"] == f"{says} they end"
            assert (third["status"], third["queue_position"]) == ("queued", 2)
            assert "queued behind 2 atlas jobs (1 computing" in third["message"]
            first = client.get(f"/atlas/{ids[0]}").json()
            assert first["queue_position"] is None and first["message"] == "computing"
            client.delete(f"/atlas/{ids[0]}")
            deadline = time.monotonic() + 60
            while client.get(f"/atlas/{ids[1]}").json()["status"] == "queued":
                assert time.monotonic() < deadline
                assert client.get(f"/atlas/{ids[2]}").json()["status"] == "queued"
                time.sleep(0.05)
        finally:
            for job in ids:
                client.delete(f"/atlas/{job}")


def test_a_forwarded_for_header_does_not_make_a_new_client():
    """Without --forwarded-allow-ips the client is the connection's peer: X-Forwarded-For
    cannot lift the per-client atlas limit (2), which a new address per request did."""
    from jik.benchmarks.serving import jik_serve

    with jik_serve(JIK_WORKERS="1") as served, httpx.Client(base_url=served.url, timeout=120) as c:
        ids = []
        try:
            for k, body in enumerate([LONG_ATLAS, SHORT_ATLAS]):
                r = c.post("/atlas", json=body, headers={"X-Forwarded-For": f"203.0.113.{k}"})
                assert r.status_code == 202, r.text
                ids.append(r.json()["id"])
            r = c.post("/atlas", json=SHORT_ATLAS, headers={"X-Forwarded-For": "203.0.113.9"})
            assert r.status_code == 429, r.text
            assert "at most 2 atlas jobs per client" in r.json()["detail"]
        finally:
            for job in ids:
                c.delete(f"/atlas/{job}")
