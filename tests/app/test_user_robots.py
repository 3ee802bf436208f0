"""User robots through REST: a planar chain, a formula robot and a URDF arm in
/solve, /repeatability and /synthesize, and the refusals of bad or hostile definitions."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from jik.engine.kinematics import Manipulator2
from tests.app.conftest import messages
from tests.engine.test_planar_chain import _ivp_legs

ARM = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
X0 = [0.3, 1.0, 1.0]
#: A closed path around k(X0) = (0.770, 1.514), as in tests/engine/test_planar_chain.py.
PATH = [[1.0, 1.3], [1.0, 1.7], [0.6, 1.7]]
REGION = {"x2": [0.4, 2.0], "x3": [0.4, 2.0]}
M2_FORMULA = {
    "name": "formula",
    "variables": ["x1", "x2", "x3"],
    "task": ["x2 + l*cos(x3)", "x1 + l*sin(x3)"],
    "parameters": {"l": 1.0},
}
ARM4 = Path(__file__).resolve().parents[1] / "data" / "arm4.urdf"
TABLE1_PATH = [[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 1.0]]


def _ok(response) -> dict:
    assert response.status_code == 200, response.text
    return response.json()


def test_planar_3r_solve_reaches_the_target(api):
    b = _ok(
        api.post(
            "/solve",
            json={"robot": ARM, "algorithm": "pseudoinverse", "x0": X0, "target": [1.0, 1.3]},
        )
    )
    assert b["converged"] and b["error"] < 1e-10
    assert b["robot"]["name"] == "planar_chain" and (b["robot"]["p"], b["robot"]["r"]) == (3, 2)
    assert b["robot"]["definition"]["lengths"] == [1.0, 0.8, 0.6]
    x = np.array(b["x"])
    y = np.array(
        [
            np.cos(x[0]) + 0.8 * np.cos(x[0] + x[1]) + 0.6 * np.cos(x.sum()),
            np.sin(x[0]) + 0.8 * np.sin(x[0] + x[1]) + 0.6 * np.sin(x.sum()),
        ]
    )
    np.testing.assert_allclose(y, [1.0, 1.3], atol=1e-9)
    lower = {**ARM, "joints": "rrr"}  # (the engine's PlanarChain takes either case)
    same = _ok(
        api.post(
            "/solve",
            json={"robot": lower, "algorithm": "pseudoinverse", "x0": X0, "target": [1.0, 1.3]},
        )
    )
    assert same["x"] == b["x"]


def test_planar_3r_pseudoinverse_legs_match_an_independent_solve_ivp(api):
    """Two cycles: the leg ends through REST are scipy's own integration of eq. (7) to 1e-8."""
    b = _ok(
        api.post(
            "/repeatability",
            json={"robot": ARM, "algorithm": "pseudoinverse", "x0": X0, "path": PATH, "cycles": 2},
        )
    )
    from jik.engine.planar_chain import PlanarChain

    arm = PlanarChain("RRR", [1.0, 0.8, 0.6])
    reference = _ivp_legs(arm, np.array(X0), [*b["targets"], *b["targets"]])
    np.testing.assert_allclose(np.array(b["legs"]), reference, atol=1e-8, rtol=0)
    assert b["drift"][0] > 1e-3 and not b["repeatable"]


def test_planar_3r_synthesis_then_its_extended_inverse_is_repeatable(api):
    """e2_variational on the box; E2 below that of h = x3 there; the extended inverse of the
    synthesized map drives the path 5 times back to x0 (drift < 1e-9)."""
    synth = _ok(
        api.post(
            "/synthesize",
            json={
                "robot": ARM,
                "method": "e2_variational",
                "region": REGION,
                "degree": 12,
                "nodes": 16,
            },
        )
    )
    x3 = _ok(
        api.post(
            "/synthesize",
            json={
                "robot": ARM,
                "method": "evaluate",
                "region": REGION,
                "augmentation": {"name": "formula", "h": "x3"},
                "nodes": 16,
            },
        )
    )
    e2, e2_x3 = synth["functionals"]["e2"]["value"], x3["functionals"]["e2"]["value"]
    assert e2 < 0.2 * e2_x3, (e2, e2_x3)
    assert x3["augmentation"]["definition"] == {"name": "formula", "h": "x3"}
    rep = _ok(
        api.post(
            "/repeatability",
            json={
                "robot": ARM,
                "algorithm": "extended",
                "x0": X0,
                "path": PATH,
                "cycles": 5,
                "augmentation": {"name": "e2_synthesized", "region": REGION, "degree": 12},
            },
        )
    )
    assert rep["success"] and rep["repeatable"]
    assert max(rep["drift"]) < 1e-9
    assert rep["augmentation"]["name"] == "e2_synthesized"


def test_more_than_one_degree_of_redundancy_is_refused_by_e2_variational(api):
    arm = {"name": "planar_chain", "joints": "RRRR", "lengths": [0.5, 0.5, 0.5, 0.5]}
    r = api.post(
        "/synthesize",
        json={"robot": arm, "method": "e2_variational", "region": {"x3": [0, 1], "x4": [0, 1]}},
    )
    (msg,) = messages(r)
    assert msg.startswith("method: 'e2_variational' synthesizes one map h")
    assert "p = 4, r = 2" in msg


@pytest.mark.parametrize(
    "augmentation", [{"name": "formula", "h": "x1"}, {"name": "e2_synthesized", "region": REGION}]
)
def test_a_chain_without_redundancy_refuses_a_map_saying_why(api, augmentation):
    """p = r (a 2R chain): no map fits, as Robot.inverse('extended') says; the answer said
    'must be a list of 0 formulas' (and asked e2_variational for '0 formula maps instead')."""
    arm = {"name": "planar_chain", "joints": "RR", "lengths": [1.0, 1.0]}
    body = {"robot": arm, "algorithm": "extended", "augmentation": augmentation}
    (msg,) = messages(api.post("/solve", json=body))
    assert msg.startswith("augmentation: an augmenting map needs redundancy (p > r)")
    assert "p = r = 2" in msg and "0 formulas" not in msg
    region = {"x1": [0, 1], "x2": [0, 1]}
    body = {"robot": arm, "method": "e2_variational", "region": region}
    (msg,) = messages(api.post("/synthesize", json=body))
    assert msg.startswith("method: 'e2_variational' synthesizes one map h")
    assert "p = 2, r = 2: its Jacobian is square" in msg and "0 formula maps" not in msg


def test_a_formula_robot_undefined_at_the_default_start_runs_from_the_requests_x0(api):
    """log(x1 - 100) is undefined at the default start (0.5, 0.5, 0.5) and across the default
    box: the robot was refused ('give an x0 where it is defined') though the request gave one,
    and a definition over REST takes no x0 ('unknown field'). The request's x0 starts it, as
    the definition's x0 does in Python."""
    robot = {"name": "formula", "variables": ["x1", "x2", "x3"]}
    robot["task"] = ["log(x1 - 100) + x3", "x2"]
    body = {"robot": robot, "algorithm": "pseudoinverse", "x0": [200, 0, 0], "target": [4.7, 0.1]}
    res = _ok(api.post("/solve", json=body))
    assert res["converged"] and np.allclose(res["y"], [4.7, 0.1], atol=1e-9)
    assert "x0" not in res["robot"]["definition"]  # (the definition as given)
    k = _ok(api.post("/kinematics", json={"robot": robot, "x": [[200, 0, 0], [300, 0, 1]]}))
    assert np.allclose(k["k"], [[math.log(100), 0], [math.log(200) + 1, 0]])
    (msg,) = messages(api.post("/solve", json={**body, "x0": None}))  # (no start: refused)
    assert msg.startswith("robot: the task k(x) is undefined at x0 = (0.5, 0.5, 0.5)")
    (msg,) = messages(api.post("/solve", json={**body, "x0": [50, 0, 0]}))  # (undefined there)
    assert msg.startswith("robot: the task k(x) is undefined at x0 = (0.5, 0.5, 0.5)")


def test_formula_manipulator2_equals_the_builtin(api):
    """Manipulator 2 written as formulas gives the built-in's Table 1 run to 1e-9."""
    for algorithm, aug in (("pseudoinverse", None), ("extended", "x3 - 0.7501*x2*x3")):
        results = []
        for robot, augmentation in (
            (M2_FORMULA, {"name": "formula", "h": aug}),
            ({"name": "manipulator2", "l": 1.0}, None),
        ):
            body = {
                "robot": robot,
                "algorithm": algorithm,
                "x0": [0.0, 0.0, math.pi / 2],
                "path": TABLE1_PATH,
                "cycles": 2,
            }
            if aug is not None and augmentation is not None:
                body["augmentation"] = augmentation
            results.append(_ok(api.post("/repeatability", json=body)))
        if algorithm == "extended":
            continue  # (the built-in's default map is the paper's cubic, not this one)
        np.testing.assert_allclose(results[0]["legs"], results[1]["legs"], atol=1e-9, rtol=0)
    b = _ok(
        api.post(
            "/solve",
            json={
                "robot": M2_FORMULA,
                "algorithm": "pseudoinverse",
                "x0": [0.0, 0.0, 1.5],
                "target": [1.0, 1.0],
            },
        )
    )
    ref = _ok(
        api.post(
            "/solve",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": "pseudoinverse",
                "x0": [0.0, 0.0, 1.5],
                "target": [1.0, 1.0],
            },
        )
    )
    np.testing.assert_allclose(b["x"], ref["x"], atol=1e-9, rtol=0)
    np.testing.assert_allclose(Manipulator2().forward(np.array(b["x"])), [1.0, 1.0], atol=1e-9)


def test_urdf_arm_solve_and_repeatability(api):
    pytest.importorskip("yourdfpy")
    robot = {"name": "urdf", "urdf": ARM4.read_text(), "end_link": "tool"}
    x0 = [0.3, 0.5, 0.8, 0.6]
    solved = _ok(
        api.post(
            "/solve",
            json={
                "robot": robot,
                "algorithm": "pseudoinverse",
                "x0": x0,
                "target": [0.2, 0.1, 0.8],
            },
        )
    )
    assert solved["converged"] and (solved["robot"]["p"], solved["robot"]["r"]) == (4, 3)
    start = np.array(solved["trajectory"]["y"][0])
    path = [list(start + [0.05, 0, 0]), list(start + [0.05, 0.05, 0]), list(start + [0, 0.05, 0])]
    rep = _ok(
        api.post(
            "/repeatability",
            json={
                "robot": robot,
                "algorithm": "extended",
                "augmentation": {"name": "formula", "h": "x4 - x3"},
                "x0": x0,
                "path": path,
                "cycles": 3,
            },
        )
    )
    assert rep["success"] and max(rep["drift"]) < 1e-9


def test_a_urdf_is_not_echoed_and_skipped_meshes_are_noted(api):
    pytest.importorskip("yourdfpy")
    text = ARM4.read_text().replace(
        '<link name="tool"/>',
        '<link name="tool"><visual><geometry>'
        '<mesh filename="file:///etc/passwd"/></geometry></visual>'
        "</link>",
    )
    robot = {"name": "urdf", "urdf": text, "end_link": "tool"}
    run = {
        "robot": robot,
        "algorithm": "pseudoinverse",
        "x0": [0.3, 0.5, 0.8, 0.6],
        "target": [0.2, 0.1, 0.8],
    }
    response = api.post("/solve", json=run)
    body = _ok(response)
    assert "<robot" not in response.text and "link name" not in response.text
    assert body["robot"]["definition"]["urdf_bytes"] == len(text.encode())
    assert body["robot"]["definition"]["end_link"] == "tool"
    assert "1 mesh file reference(s) skipped, never read" in body["robot"]["notes"][0]
    # an atlas job names the same robot, notes included, and not its text either
    atlas = {"robot": robot, "reference": run["x0"], "starts": 2, "cycles": 1, "arc": [-0.1, 0.1]}
    job = api.post("/atlas", json=atlas)
    assert job.status_code == 202, job.text
    assert job.json()["robot"] == body["robot"] and "<robot" not in job.text


def test_vector_lengths_are_checked_against_the_built_robot(api):
    body = {"robot": ARM, "algorithm": "pseudoinverse", "x0": [0.3, 1.0], "target": [1.0, 1.3]}
    assert messages(api.post("/solve", json=body)) == [
        "x0: must have 3 components (this planar_chain robot has p = 3, r = 2), got 2"
    ]
    body = {"robot": ARM, "algorithm": "pseudoinverse", "x0": X0, "path": [[1.0, 1.3, 0.0]]}
    assert messages(api.post("/repeatability", json=body)) == [
        "path[0]: must have 2 components (this planar_chain robot has p = 3, r = 2), got 3"
    ]


@pytest.mark.parametrize(
    ("robot", "field", "text"),
    [
        ({**ARM, "lengths": [1.0, 0.8]}, "robot.lengths", "one entry per joint (3), got 2"),
        ({**ARM, "joints": "RXR"}, "robot.joints", "String should match pattern"),
        ({**M2_FORMULA, "task": ["x2 +* x3", "x1"]}, "robot.task[0]", "expected a number"),
        (
            {"name": "urdf", "urdf": "<robot name='a'><link name='b'/></robot>", "end_link": "c"},
            "robot.end_link",
            "'c' is not a link",
        ),
        ({"name": "urdf", "urdf": "not xml", "end_link": "c"}, "robot.urdf", "not a valid URDF"),
        (
            {
                "name": "urdf",
                "urdf": ARM4.read_text().replace('<axis xyz="0 1 0"/>', '<axis xyz="0 1"/>'),
                "end_link": "tool",
            },
            "robot.urdf",
            "joint 'shoulder' has axis xyz='0 1', not 3 numbers",
        ),
    ],
)
def test_bad_definitions_are_422_naming_the_field(api, robot, field, text):
    body = {"robot": robot, "algorithm": "pseudoinverse", "x0": X0, "target": [1.0, 1.3]}
    r = api.post("/solve", json=body)
    (msg,) = messages(r)
    assert msg.startswith(f"{field}: ") and text in msg, msg
    loc = [str(p) for p in r.json()["detail"][0]["loc"]]
    assert loc == ["body", *field.replace("[", ".").replace("]", "").split(".")]


HOSTILE = [
    "__import__('os')",
    "x1.real",
    "lambda: 1",
    "[x for x in (1, 2)]",
    "x1**10**10",
    "x1 + " * 20_000 + "x1",  # (100 kB)
    "open + x1",
    "y + x1",
]


@pytest.mark.parametrize("formula", HOSTILE, ids=lambda f: f[:20])
def test_hostile_formulas_are_422_in_the_task_and_in_h(api, formula):
    robot = {**M2_FORMULA, "task": [formula, "x1 + sin(x3)"]}
    r = api.post(
        "/solve",
        json={
            "robot": robot,
            "algorithm": "pseudoinverse",
            "x0": [0.0, 0.0, 1.5],
            "target": [1.0, 1.0],
        },
    )
    (msg,) = messages(r)
    assert msg.startswith("robot.task[0]: "), msg
    r = api.post(
        "/solve",
        json={
            "robot": M2_FORMULA,
            "algorithm": "extended",
            "augmentation": {"name": "formula", "h": formula},
            "x0": [0.0, 0.0, 1.5],
            "target": [1.0, 1.0],
        },
    )
    # (h is a formula or a list of them: a text too long is refused as both)
    assert all(m.startswith("augmentation.h: ") for m in messages(r)), r.text


def test_a_synthesized_vector_map_runs_over_rest(api):
    """p - r = 2: a planar 4R chain's ``e2_synthesized`` map is the vector (h_1, h_2) of the
    total-degree synthesis (default degree 4, reported); its extended run is repeatable."""
    box = {"x1": [0.1, 0.5], "x2": [0.4, 0.8], "x3": [0.4, 0.8], "x4": [0.4, 0.8]}
    chain = {"name": "planar_chain", "joints": "RRRR", "lengths": [1, 1, 1, 1]}
    x0 = [0.3, 0.6, 0.6, 0.6]
    start = np.array(
        _ok(
            api.post(
                "/solve",
                json={"robot": chain, "algorithm": "pseudoinverse", "x0": x0, "target": [1, 1]},
            )
        )["trajectory"]["y"][0]
    )
    path = [list(start + [0.1, 0]), list(start + [0.1, 0.1]), list(start + [0, 0.1])]
    rep = _ok(
        api.post(
            "/repeatability",
            json={
                "robot": chain,
                "algorithm": "extended",
                "x0": x0,
                "path": path,
                "cycles": 3,
                "augmentation": {"name": "e2_synthesized", "region": box},
            },
        )
    )
    assert rep["success"] and max(rep["drift"]) < 1e-9
    assert rep["augmentation"]["definition"]["degree"] == 4


def test_a_vector_maps_trajectory_matches_the_published_schema(api):
    """The extended run of a map of p - r = 2 components gives h as one pair per point, and the
    response is what SolveResponse (the published schema) describes."""
    from jik.app.compute.schemas import SolveResponse

    chain = {"name": "planar_chain", "joints": "RRRR", "lengths": [1, 1, 1, 1]}
    body = {
        "robot": chain,
        "algorithm": "extended",
        "augmentation": {"name": "formula", "h": ["x1", "x2"]},
        "x0": [0.3, 0.6, 0.6, 0.6],
        "target": [1.5, 1.5],
    }
    out = _ok(api.post("/solve", json=body))
    h = np.array(out["trajectory"]["h"])
    assert h.shape == (len(out["trajectory"]["theta"]), 2)
    np.testing.assert_allclose(h, [[0.3, 0.6]] * len(h), atol=1e-9)
    SolveResponse.model_validate(out)


def test_a_refused_map_is_named_once_by_the_requests_field(api):
    """The engine names the definition's field (augmentations.0.h); the answer names the
    request's (augmentation.h), once, not both."""
    body = {
        "robot": {"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1]},
        "algorithm": "extended",
        "augmentation": {"name": "formula", "h": ["x1", "x2"]},
        "x0": [0.3, 0.6, 0.6],
        "target": [1.0, 1.0],
    }
    r = api.post("/solve", json=body)
    assert r.status_code == 422
    assert messages(r) == ["augmentation.h: must be a formula (a string), got list"]


def test_a_urdf_over_100_kb_is_taken_as_in_python_and_the_dashboard(api):
    """A real robot's URDF (Talos' is 111 kB) is taken up to the engine's MAX_URDF_BYTES, the
    bound of Python and the dashboard, whose atlas sends its robot through this API."""
    pytest.importorskip("yourdfpy")
    text = ARM4.read_text().replace("<robot", "<!--" + "pad " * 40_000 + "-->\n<robot", 1)
    assert len(text) > 150_000
    robot = {"name": "urdf", "urdf": text, "end_link": "tool"}
    body = _ok(api.post("/kinematics", json={"robot": robot, "x": [0.3, 0.5, 0.8, 0.6]}))
    assert body["robot"]["definition"]["urdf_bytes"] == len(text)


def test_a_urdf_chain_starts_at_the_base_link_it_is_given(api):
    """base_link starts the chain past a floating root (a humanoid's torso): refused without
    it, naming the link to give, and answered with it."""
    pytest.importorskip("yourdfpy")
    from tests.engine.test_urdf import _FLOATING

    robot = {"name": "urdf", "urdf": _FLOATING, "end_link": "hand", "task": "xy"}
    body = {"robot": robot, "x": [0.3, -0.4, 0.5]}
    (error,) = api.post("/kinematics", json=body).json()["detail"]
    assert "joint 'root' on the chain is floating" in error["msg"]
    assert "base_link 'torso'" in error["msg"]
    answer = _ok(api.post("/kinematics", json={**body, "robot": {**robot, "base_link": "torso"}}))
    assert answer["robot"]["p"] == 3 and answer["robot"]["definition"]["base_link"] == "torso"
