"""Shared fixtures of the API tests: an app with its lifespan per session (``api``), an app
per module whose tests each have their own sessions and atlas jobs (``app``)."""

from __future__ import annotations

import math

import pytest
from fastapi.testclient import TestClient

from jik.app.api.factory import create_app
from jik.app.compute.pool import ComputePool
from jik.app.compute.settings import Settings

X0_M2 = [0.0, 0.0, math.pi / 2]
TABLE1_PATH = [[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 1.0]]


@pytest.fixture(autouse=True)
def _pools_end_with_their_test(monkeypatch):
    """The compute pools a test makes stop their workers when it ends: an app used without its
    lifespan never closes its pool, whose workers would otherwise stay, idle, until pytest's
    process exits (by the dozen, with their memory). Pools of broader fixtures, made before
    this one, are theirs to close."""
    made: list[ComputePool] = []
    init = ComputePool.__init__

    def recorded(self, *args, **kwargs):
        init(self, *args, **kwargs)
        made.append(self)

    monkeypatch.setattr(ComputePool, "__init__", recorded)
    yield
    for pool in made:
        pool.close()


@pytest.fixture(scope="session")
def api():
    """httpx-based TestClient driving the ASGI app (lifespan on: workers started and stopped)."""
    with TestClient(create_app(Settings(workers=2, timeout=60.0))) as client:
        yield client


@pytest.fixture(scope="module")
def module_app():
    """One app for a module's tests, without its lifespan: its compute pool serves them all (a
    pool's worker takes about a second of imports to start)."""
    app = create_app()
    yield app
    app.state.pool.close()


@pytest.fixture
def app(module_app, request):
    """The module's app with this test's own dashboard sessions (at most 4, no 3D scene: they
    compute in their own threads) and atlas jobs: made on first use, or by the module's
    ``ATLAS_LIMITS`` (jobs that run in the test's process)."""
    from jik.app.compute.atlas_jobs import AtlasJobs
    from jik.app.dashboard.sessions import SessionStore

    limits = getattr(request.module, "ATLAS_LIMITS", None)
    made = None if limits is None else AtlasJobs(limits)
    module_app.state.sessions = SessionStore(Settings(max_sessions=4))
    module_app.state.atlas_jobs = made
    yield module_app
    module_app.state.sessions.close()
    for jobs in (made, module_app.state.atlas_jobs):  # (a test may have put its own)
        if jobs is not None:
            jobs.close()


@pytest.fixture
def client(app):
    return TestClient(app)


def solve_body(**over) -> dict:
    """A valid /solve request for Manipulator 2 (Table 1's start), with overrides."""
    body = {
        "robot": {"name": "manipulator2", "l": 1.0},
        "algorithm": "pseudoinverse",
        "x0": X0_M2,
        "target": [1.0, 1.0],
    }
    body.update(over)
    return body


def messages(response) -> list[str]:
    """The ``msg`` of every error of a 422 response."""
    assert response.status_code == 422, response.text
    return [e["msg"] for e in response.json()["detail"]]
