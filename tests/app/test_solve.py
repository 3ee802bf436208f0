"""POST /solve: numbers, trajectories, defaults, and the batched path."""

from __future__ import annotations

import asyncio
import json
import math

import httpx
import numpy as np
import pytest

from jik.app.api.factory import create_app
from jik.app.compute.settings import Settings
from tests.app.conftest import X0_M2, solve_body
from tests.helpers import run_async

# Table 1, pseudoinverse column, first leg: x1f after (0, 1) -> (1, 1).
X1F = [0.1132, 0.5379, 1.0904]


def test_solve_pseudoinverse_manipulator2(api):
    r = api.post("/solve", json=solve_body())
    assert r.status_code == 200, r.text
    b = r.json()
    assert b["converged"] is True and b["status"] == "converged"
    assert b["message"].startswith("converged")
    np.testing.assert_allclose(b["x"], X1F, atol=6e-5)
    np.testing.assert_allclose(b["y"], [1.0, 1.0], atol=1e-9)
    assert b["error"] < 1e-10
    assert b["mode"] == "continuous" and b["gamma"] == 1.0
    t = b["trajectory"]
    m = len(t["theta"])
    assert m == t["points"] > 10 and not t["downsampled"]
    assert len(t["x"]) == len(t["y"]) == len(t["error"]) == m
    assert t["h"] is None
    np.testing.assert_allclose(t["x"][0], X0_M2)
    assert t["error"][-1] == b["error"]
    assert np.all(np.diff(t["theta"]) > 0)
    # the task error decays like exp(-gamma theta), eq. (6)
    e = np.array(t["error"])
    np.testing.assert_allclose(e, e[0] * np.exp(-np.array(t["theta"])), rtol=1e-6, atol=1e-11)


def test_solve_extended_keeps_h_constant(api):
    """Extended inverse (11): h(x) is constant along the run, eq. (12)."""
    r = api.post("/solve", json=solve_body(algorithm="extended"))
    b = r.json()
    assert r.status_code == 200 and b["converged"]
    assert b["augmentation"] == {"name": "paper_cubic", "parameters": {}}
    h = np.array(b["trajectory"]["h"])
    assert h.shape == (len(b["trajectory"]["theta"]),)
    assert np.ptp(h) < 1e-9


def test_solve_manipulator1_with_parameters_and_discrete_mode(api):
    body = {
        "robot": {"name": "manipulator1"},
        "algorithm": "extended",
        "augmentation": {"name": "e1_optimal", "C1": 2.0},
        "x0": [0.5, 0.5, 1.0],
        "target": [0.8, 1.5],
        "mode": "discrete",
        "gamma": 0.5,
        "tolerance": 1e-8,
    }
    b = api.post("/solve", json=body).json()
    assert b["augmentation"] == {"name": "e1_optimal", "parameters": {"C1": 2.0, "C2": 1.0}}
    assert b["mode"] == "discrete" and b["converged"]
    assert b["error"] < 1e-8
    # iterations are numbered 0, 1, 2, ...
    np.testing.assert_allclose(b["trajectory"]["theta"], np.arange(len(b["trajectory"]["theta"])))
    assert b["iterations"] == len(b["trajectory"]["theta"]) - 1


def test_solve_not_converged_is_200_with_reason(api):
    """A run that hits max_iterations is a result (converged false), not an error."""
    b = api.post("/solve", json=solve_body(max_iterations=3)).json()
    assert b["converged"] is False and b["status"] == "max_steps"
    assert "did not converge within 3 steps" in b["message"]


def test_a_stalled_solve_says_why(api):
    """A planar 3R arm of reach 2.4 asked for a target at 5: the response's message says the
    target is out of reach (the engine's diagnosis, the same words as the dashboard's)."""
    arm = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    body = solve_body(robot=arm, x0=[0.3, 0.4, 0.5], target=[5.0, 0.0])
    b = api.post("/solve", json=body).json()
    assert b["converged"] is False and b["message"].startswith("stalled after ")
    assert b["status"] == "stalled"  # (the engine's SolveResult.status, for a client's branch)
    assert (
        "the target is out of reach: it is 5 from the base, beyond the arm's reach 2.4"
        in (b["message"])
    )


def test_gamma_only_rescales_theta(api):
    """Continuous mode: x(theta) does not depend on gamma, theta scales as 1/gamma (NOTES.md)."""
    a = api.post("/solve", json=solve_body(gamma=1.0)).json()
    b = api.post("/solve", json=solve_body(gamma=4.0)).json()
    np.testing.assert_allclose(a["x"], b["x"], atol=1e-12)
    np.testing.assert_allclose(np.array(a["trajectory"]["theta"]) / 4, b["trajectory"]["theta"])


async def _concurrent(app, bodies):
    transport = httpx.ASGITransport(app=app)
    async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as client:
        return await asyncio.gather(*(client.post("/solve", json=b) for b in bodies))


def _post_concurrently(settings: Settings, bodies: list[dict]):
    """POST every body at once to a fresh app with ``settings``; its responses and pool stats."""
    app = create_app(settings)
    try:
        return run_async(_concurrent(app, bodies)), dict(app.state.pool.stats)
    finally:
        app.state.pool.close()


def test_concurrent_solves_are_batched_and_equal_to_single_solves(api):
    """16 concurrent compatible requests share few engine calls; each result is its own."""
    rng = np.random.default_rng(1)
    targets = rng.uniform([0.2, 0.8], [1.2, 1.8], size=(16, 2))
    bodies = [solve_body(target=t.tolist()) for t in targets]
    responses, stats = _post_concurrently(
        Settings(workers=1, timeout=60.0, batch_window_ms=5), bodies
    )
    assert [r.status_code for r in responses] == [200] * 16
    assert stats["solve_requests"] == 16
    assert stats["solve_calls"] <= 4, stats
    for body, r in zip(bodies, responses, strict=True):
        single = api.post("/solve", json=body).json()
        np.testing.assert_allclose(r.json()["x"], single["x"], atol=1e-12)
        np.testing.assert_allclose(r.json()["y"], body["target"], atol=1e-9)


def test_a_large_batch_is_shared_among_idle_workers(api):
    """16 requests in one window with two idle workers: two engine calls of 8, same results."""
    rng = np.random.default_rng(2)
    bodies = [solve_body(target=t.tolist()) for t in rng.uniform([0.2, 0.8], [1.2, 1.8], (16, 2))]
    responses, stats = _post_concurrently(
        Settings(workers=2, timeout=60.0, batch_window_ms=50), bodies
    )
    assert [r.status_code for r in responses] == [200] * 16
    assert (stats["solve_calls"], stats["solve_requests"]) == (2, 16), stats
    for body, r in zip(bodies, responses, strict=True):
        single = api.post("/solve", json=body).json()
        np.testing.assert_allclose(r.json()["x"], single["x"], atol=1e-12)


def test_unbatched_mode_makes_one_call_per_request():
    bodies = [solve_body(target=[0.5 + 0.1 * i, 1.5]) for i in range(4)]
    responses, stats = _post_concurrently(Settings(workers=1, timeout=60.0, batching=False), bodies)
    assert all(r.status_code == 200 for r in responses)
    assert stats["solve_calls"] == stats["solve_requests"] == 4


def test_a_bad_member_does_not_spoil_its_batch():
    """One singular start among compatible requests: 422 for it, 200 for the others."""
    good = {
        "robot": {"name": "manipulator1"},
        "algorithm": "extended",
        "augmentation": {"name": "e2_optimal", "a": 1.0, "b": 0.0},
        "x0": [0.5, 0.5, 1.0],
        "target": [0.8, 1.5],
    }
    bad = {**good, "x0": [0.0, 0.5, 1.0]}  # dh K = 0 at x1 = -b/a = 0
    responses, stats = _post_concurrently(
        Settings(workers=1, timeout=60.0, batch_window_ms=10), [good, bad, good]
    )
    assert [r.status_code for r in responses] == [200, 422, 200]
    assert stats["solve_calls"] == 1
    assert "algorithmic singularity" in responses[1].json()["detail"][0]["msg"]
    assert math.isclose(responses[0].json()["x"][0], 0.8, abs_tol=1e-9)


def test_a_start_where_the_map_has_no_real_value_is_a_422_naming_x0(api):
    """h = log(x3) at x3 = -1 (its gradient 1/x3 finite): the engine's solve refuses the start,
    and so does the answer, naming x0, as /repeatability's does."""
    robot = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["x1 + x3", "x2"]}
    body = {
        "robot": robot,
        "algorithm": "extended",
        "augmentation": {"name": "formula", "h": "log(x3)"},
        "x0": [0.0, 0.0, -1.0],
    }
    for route, more in (("/solve", {"target": [1, 1]}), ("/repeatability", {"path": [[1, 1]]})):
        r = api.post(route, json={**body, **more})
        assert r.status_code == 422, r.text
        (detail,) = r.json()["detail"]
        assert detail["loc"] == ["body", "x0"], r.text
        assert "the augmenting map has no real value at the start" in detail["msg"]


def test_every_registered_robot_solves_with_its_defaults(api):
    """Default start and target of every robot in the registry, its default mode and gamma
    (continuous, 1 for the manipulators; discrete, 0.1 for the unicycle once registered)."""
    from jik.engine.registry import ROBOTS

    for name, spec in ROBOTS.items():
        body = {
            "robot": {"name": name},
            "algorithm": "pseudoinverse",
            "x0": list(spec.default_x0),
            "target": list(spec.default_target),
        }
        r = api.post("/solve", json=body)
        assert r.status_code == 200, (name, r.text)
        b = r.json()
        assert (b["mode"], b["gamma"]) == (spec.default_mode, spec.default_gamma), name
        assert b["converged"], (name, b["message"])
        assert len(b["x"]) == spec.p and len(b["y"]) == spec.r
        np.testing.assert_allclose(b["y"], spec.default_target, atol=1e-9)


def test_service_batch_isolates_a_bad_first_member():
    """The plain service function (the workers'): a wrong-length first member gets its own
    error, the others are solved."""
    from jik.app.compute.exceptions import RequestError
    from jik.app.compute.requests import solve_batch_json
    from jik.app.compute.schemas import SolveRequest

    reqs = [
        SolveRequest.model_validate(solve_body(x0=[0.0, 0.0])),
        SolveRequest.model_validate(solve_body()),
        SolveRequest.model_validate(solve_body(target=[0.5, 1.5])),
    ]
    out = solve_batch_json(reqs)
    assert isinstance(out[0], RequestError) and out[0].field == "x0"
    np.testing.assert_allclose(json.loads(out[1])["x"], X1F, atol=6e-5)
    np.testing.assert_allclose(json.loads(out[2])["y"], [0.5, 1.5], atol=1e-9)


def test_a_start_on_the_rotation_coordinates_cut_spoils_only_its_own_request():
    """A Panda start a half turn from R0 (the base frame: home, flange down) is refused by the
    engine's check of starts, which refuses a whole batch: each member is checked alone."""
    pytest.importorskip("yourdfpy")
    from jik.app.compute.exceptions import RequestError
    from jik.app.compute.requests import solve_batch_json
    from jik.app.compute.schemas import SolveRequest
    from jik.engine import robot_from_dict

    robot = {"name": "panda", "task": "pose", "reference": [0, 0, 0]}
    panda = robot_from_dict(robot)
    home = np.array(panda.spec.default_x0)
    near = home + [0, 0, 0, 0, 0, 0.3, 0]
    body = {"robot": robot, "algorithm": "pseudoinverse", "x0": list(near)}
    target = list(panda.kinematics.forward(near) + [0.02, 0, 0, 0, 0, 0])
    reqs = [
        SolveRequest.model_validate({**body, "target": target}),
        SolveRequest.model_validate({**body, "x0": list(home), "target": target}),
    ]
    first, second = solve_batch_json(reqs)
    assert isinstance(second, RequestError) and second.field == "x0"
    assert "a half turn from the reference orientation R0" in str(second)
    np.testing.assert_allclose(json.loads(first)["y"], target, atol=1e-9)


@pytest.mark.parametrize(
    "over",
    [
        {},
        {"algorithm": "extended", "augmentation": {"name": "paper_cubic"}},
        {"algorithm": "extended", "augmentation": {"name": "e2_synthesized"}},
        {"mode": "discrete", "gamma": 0.5},
        {"mode": "discrete", "gamma": 1e-3, "max_iterations": 2500},  # downsampled trajectory
        {"max_iterations": 3, "target": [1.9, 0.6]},  # not converged
        {"robot": {"name": "manipulator1"}, "x0": [0.3, 0.2, 0.1], "target": [0.5, 0.4]},
    ],
)
def test_worker_json_is_the_validated_response(over):
    """The workers' JSON (built without pydantic) is the validated model's document: the same
    keys and the same float values (only the spelling of exponents differs)."""
    from jik.app.compute.requests import solve_batch_json
    from jik.app.compute.schemas import SolveRequest, SolveResponse

    req = SolveRequest.model_validate(solve_body(**over))
    (raw,) = solve_batch_json([req])
    assert isinstance(raw, bytes)
    model = SolveResponse.model_validate_json(raw)
    assert json.loads(raw) == json.loads(model.model_dump_json())
