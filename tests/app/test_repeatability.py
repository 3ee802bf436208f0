"""POST /repeatability: Table 1 through the API, and the extended inverse's repeatability."""

from __future__ import annotations

import numpy as np

from jik.engine.reproductions.table1 import PRINTED
from tests.app.conftest import TABLE1_PATH, X0_M2


def _body(**over) -> dict:
    body = {
        "robot": {"name": "manipulator2"},
        "algorithm": "pseudoinverse",
        "x0": X0_M2,
        "path": TABLE1_PATH,
        "cycles": 1,
    }
    body.update(over)
    return body


def test_table1_pseudoinverse_column(api):
    """The four legs of Table 1 reproduce the printed pseudoinverse column to four decimals."""
    r = api.post("/repeatability", json=_body())
    assert r.status_code == 200, r.text
    b = r.json()
    np.testing.assert_allclose(b["legs"], PRINTED["pseudoinverse"][1:], atol=6e-5)
    np.testing.assert_allclose(b["targets"], TABLE1_PATH)  # (0, 1) = k(x0) closes the path
    assert len(b["cycle_end"]) == 1 and len(b["drift"]) == 1
    np.testing.assert_allclose(b["drift"][0], np.linalg.norm(np.subtract(b["legs"][-1], X0_M2)))
    assert b["drift"][0] > 0.3  # the pseudoinverse is not repeatable
    assert b["repeatable"] is False and b["success"] is True
    assert b["stopped_at"] is None  # (every leg reached its target)


def test_a_failed_leg_says_where_it_stopped(api):
    """The extended inverse stalls at an algorithmic singularity on its first leg: no leg end
    (null), but the configuration where the leg stopped, beside the message."""
    b = api.post("/repeatability", json=_body(algorithm="extended", x0=[0, -0.69, 0.675])).json()
    assert b["success"] is False and b["message"].startswith("cycle 1, leg 1 failed: stalled")
    assert b["legs"][0] == [None] * 3
    assert 1e-4 < np.linalg.norm(np.subtract(b["stopped_at"], [0, -0.69, 0.675])) < 1e-3


def test_pseudoinverse_drift_grows_over_cycles(api):
    b = api.post("/repeatability", json=_body(cycles=3)).json()
    assert len(b["legs"]) == 12 and len(b["cycle_end"]) == 3
    np.testing.assert_allclose(b["cycle_end"], [b["legs"][3], b["legs"][7], b["legs"][11]])
    assert b["max_drift"] == max(b["drift"])
    assert not b["repeatable"]


def test_extended_inverse_drift_below_1e_8(api):
    """The extended Jacobian inverse (11) with (38) is repeatable: drift < 1e-8 every cycle."""
    b = api.post("/repeatability", json=_body(algorithm="extended", cycles=5)).json()
    assert b["success"], b["message"]
    assert len(b["drift"]) == 5
    assert max(b["drift"]) < 1e-8
    assert b["repeatable"] is True
    # the path's end points are visited, so legs land on k^-1(target) with constant h
    np.testing.assert_allclose(b["cycle_end"][-1], X0_M2, atol=1e-8)


def test_open_path_is_closed_by_the_start(api):
    """A path that does not end at k(x0) gets a return leg to k(x0)."""
    b = api.post("/repeatability", json=_body(path=[[1.0, 1.0], [1.0, 2.0]])).json()
    np.testing.assert_allclose(b["targets"], [[1.0, 1.0], [1.0, 2.0], [0.0, 1.0]], atol=1e-12)
    assert len(b["legs"]) == 3


def test_unicycle_like_defaults_come_from_the_registry(api):
    """mode and gamma default to the robot's (continuous, 1 for the manipulators)."""
    b = api.post(
        "/repeatability",
        json=_body(
            robot={"name": "manipulator1"}, x0=[0.5, 0.5, 1.0], path=[[0.8, 1.0], [0.8, 1.6]]
        ),
    ).json()
    assert b["mode"] == "continuous" and b["gamma"] == 1.0


def test_the_response_says_what_the_run_found_and_why(api):
    """``findings``: the engine's sentences (RepeatabilityResult.findings) in the robot's unit
    of the drift; J^P# drifts and says why, J^E# (11) comes back because h stayed at h(x0)
    (eq. (12)); a discrete J^E# run at gamma = 1.89 lost h and says gamma is near 2. The
    OpenAPI schema documents the list and its roles."""
    pinv = api.post("/repeatability", json=_body(cycles=2)).json()
    assert [f["role"] for f in pinv["findings"]] == ["finding", "why"]
    assert pinv["findings"][0]["text"].startswith(
        "pseudoinverse J^P#: not repeatable. After 2 cycles the joints end ‖x − x0‖ = "
        f"{pinv['drift'][-1]:.3g} [m and rad mixed] away from x0"
    )
    assert "no memory of the start" in pinv["findings"][1]["text"]
    ext = api.post("/repeatability", json=_body(algorithm="extended", cycles=2)).json()
    assert ext["findings"][0]["text"].startswith("extended Jacobian J^E#: repeatable.")
    assert ext["findings"][1]["text"].startswith("Why: J^E# adds the equation h(x) = h(x0)")
    fast = _body(algorithm="extended", cycles=3, mode="discrete", gamma=1.89)
    said = api.post("/repeatability", json=fast).json()["findings"]
    assert [f["role"] for f in said] == ["finding", "why", "note", "note"]
    assert said[1]["text"].startswith("h was not conserved")
    assert "1 − γ = -0.89 per step" in said[3]["text"]
    schema = api.get("/openapi.json").json()["components"]["schemas"]
    field = schema["RepeatabilityResponse"]["properties"]["findings"]
    assert "h stayed at h(x0), eq. (12)" in field["description"]
    assert schema["Sentence"]["properties"]["role"]["enum"] == ["finding", "why", "note", "failure"]


def test_a_practical_inverse_says_what_its_parameters_did(api):
    """``findings`` of the damped, posture and weighted inverses add what their parameters did
    (jik.engine.practical_findings.practical_findings): damped least squares' damping and task
    error at its legs' ends, the posture inverse's gain and rest (the default: x0), the weighted
    inverse's joints against the limits it took."""
    said = {}
    for algorithm, parameters in (
        ("damped", {"damping": 0.05}),
        ("posture", {"gain": 2.0}),
        ("weighted", {"limits": [[-4, 4]] * 3}),
    ):
        body = _body(algorithm=algorithm, cycles=2, algorithm_parameters=parameters)
        found = api.post("/repeatability", json=body).json()["findings"]
        assert [f["role"] for f in found] == ["finding", "why"], found
        said[algorithm] = found[1]["text"]
    assert said["damped"].startswith("damped least squares J^DLS (λ = 0.05, constant): task")
    assert said["posture"].startswith(
        "posture inverse (J^P# with a null-space pull), gain k = 2, x_rest = x0 (0, 0, 1.571)"
    )
    assert said["weighted"].startswith(
        "weighted least-norm J^W#: every joint stayed within its limits (x1 in [-4, 4];"
    )
