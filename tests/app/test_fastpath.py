"""The /solve fast path answers exactly as the FastAPI route would, for good and bad input."""

from __future__ import annotations

import json

import pytest
from fastapi.testclient import TestClient

from jik.app.api.factory import create_app
from jik.app.api.fastpath import SolveFastPath
from jik.app.compute.settings import Settings
from tests.app.conftest import solve_body

JSON = {"content-type": "application/json"}
CASES = {
    "valid": (json.dumps(solve_body()), JSON),
    "valid, charset": (
        json.dumps(solve_body(target=[0.5, 1.5])),
        {"content-type": "application/json; charset=utf-8"},
    ),
    "extended": (json.dumps(solve_body(algorithm="extended")), JSON),
    "wrong length": (json.dumps(solve_body(x0=[0.0, 0.0])), JSON),
    "NaN": (
        '{"robot": {"name": "manipulator2"}, "algorithm": "pseudoinverse", '
        '"x0": [NaN, 0, 1], "target": [1, 1]}',
        JSON,
    ),
    "unknown robot": (json.dumps(solve_body(robot={"name": "scara"})), JSON),
    "gamma <= 0": (json.dumps(solve_body(gamma=0)), JSON),
    "not JSON": ("{robot:", JSON),
    "a list": ("[1, 2]", JSON),
    "empty": ("", JSON),
    "text/plain": (json.dumps(solve_body()), {"content-type": "text/plain"}),
    "unreachable target": (json.dumps(solve_body(target=[9.0, 9.0])), JSON),
    "algorithmic singularity": (
        json.dumps(
            {
                "robot": {"name": "manipulator1"},
                "algorithm": "extended",
                "augmentation": {"name": "e2_optimal", "a": 1.0, "b": 0.0},
                "x0": [0.0, 0.5, 1.0],
                "target": [0.8, 1.5],
            }
        ),
        JSON,
    ),
}
#: Cases that pass validation and are answered by the fast path itself.
SERVED = {
    "valid",
    "valid, charset",
    "extended",
    "unreachable target",
    "algorithmic singularity",
}


def _fast_path(app) -> SolveFastPath:
    node = app.middleware_stack
    while node is not None and not isinstance(node, SolveFastPath):
        node = getattr(node, "app", None)
    assert node is not None, "no SolveFastPath in the middleware stack"
    return node


@pytest.fixture(scope="module")
def clients():
    fast = TestClient(create_app(Settings(workers=1, timeout=60.0)))
    slow = TestClient(create_app(Settings(workers=1, timeout=60.0, fast_solve=False)))
    with fast, slow:
        yield fast, slow


@pytest.mark.parametrize("case", list(CASES))
def test_fast_path_answers_as_the_route(clients, case):
    fast, slow = clients
    body, headers = CASES[case]
    served = _fast_path(fast.app).served
    a = fast.post("/solve", content=body, headers=headers)
    b = slow.post("/solve", content=body, headers=headers)
    assert (a.status_code, a.headers["content-type"]) == (b.status_code, b.headers["content-type"])
    assert a.json() == b.json()
    assert _fast_path(fast.app).served == served + (case in SERVED)
    if case in SERVED and a.status_code == 422:
        assert a.json()["detail"][0]["loc"][0] == "body"


def test_other_routes_pass_through(clients):
    fast, _ = clients
    served = _fast_path(fast.app).served
    assert fast.get("/health").json() == {"status": "ok"}
    assert fast.get("/solve").status_code == 405
    assert _fast_path(fast.app).served == served


def test_env_turns_the_fast_path_off(monkeypatch):
    monkeypatch.setenv("JIK_FAST_SOLVE", "0")
    app = create_app(Settings(workers=1))
    assert not any(m.cls is SolveFastPath for m in app.user_middleware)
    monkeypatch.delenv("JIK_FAST_SOLVE")
    app = create_app(Settings(workers=1))
    assert any(m.cls is SolveFastPath for m in app.user_middleware)
