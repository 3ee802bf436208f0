"""Units over REST: GET /robots lists each robot's variables and task coordinates with their
units (a catalogue arm's joint names, limits and home too), and every run's response says the
units of its x and y in its robot block, for catalogue robots and robots given by definition."""

from __future__ import annotations

import math

import pytest

from jik.engine.arms import ARMS

PLANAR = {"name": "planar_chain", "joints": "RPR", "lengths": [1.0, 0.8, 0.6]}
FORMULA = {
    "name": "formula",
    "variables": ["a", "b", "c"],
    "task": ["a + l*cos(c)", "b + l*sin(c)"],
    "parameters": {"l": 1.0},
}


def _ok(response) -> dict:
    assert response.status_code == 200, response.text
    return response.json()


def test_robots_lists_the_pandas_joints_with_units_limits_and_home(api):
    pytest.importorskip("yourdfpy")
    robots = {r["name"]: r for r in _ok(api.get("/robots"))["robots"]}
    panda = robots["panda"]
    assert [v["joint"] for v in panda["variables"]] == [f"panda_joint{i}" for i in range(1, 8)]
    assert {v["unit"] for v in panda["variables"]} == {"rad"}
    assert [v["home"] for v in panda["variables"]] == pytest.approx(list(ARMS["panda"].home))
    assert panda["variables"][3]["limits"] == pytest.approx([-3.0718, -0.0698])
    assert [(t["name"], t["unit"]) for t in panda["task"]] == [
        ("x", "m"),
        ("y", "m"),
        ("z", "m"),
        ("rx", "rad"),
        ("ry", "rad"),
        ("rz", "rad"),
    ]
    assert panda["lengths"].startswith("m")
    gen3 = robots["gen3"]["variables"][0]  # (a continuous joint: no bound on either side)
    assert gen3["limits"] == [None, None]


def test_robots_lists_manipulator2s_units_and_no_joints(api):
    m2 = next(r for r in _ok(api.get("/robots"))["robots"] if r["name"] == "manipulator2")
    assert [(v["name"], v["unit"]) for v in m2["variables"]] == [
        ("x1", "m"),
        ("x2", "m"),
        ("x3", "rad"),
    ]
    assert all(v["joint"] is None and v["limits"] is None for v in m2["variables"])
    assert [(t["name"], t["unit"]) for t in m2["task"]] == [("y1", "m"), ("y2", "m")]
    assert "arm length l" in m2["lengths"]


def test_a_solve_says_the_units_of_x_and_y_once(api):
    body = _ok(
        api.post(
            "/solve",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": "pseudoinverse",
                "x0": [0, 0, math.pi / 2],
                "target": [0.5, 1.5],
            },
        )
    )
    units = body["robot"]["units"]
    assert units["x"] == ["m", "m", "rad"] and units["y"] == ["m", "m"]
    assert "arm length l" in units["lengths"]


@pytest.mark.parametrize(
    ("robot", "x0", "x", "y"),
    [
        (PLANAR, [0.3, 0.2, 0.4], ["rad", "m", "rad"], ["m", "m"]),
        (FORMULA, [0.1, 0.2, 0.3], ["", "", ""], ["", ""]),
    ],
)
def test_a_user_robots_runs_say_its_units(api, robot, x0, x, y):
    """/kinematics, /solve and /repeatability of a robot given by definition."""
    kin = _ok(api.post("/kinematics", json={"robot": robot, "x": x0}))
    assert (kin["robot"]["units"]["x"], kin["robot"]["units"]["y"]) == (x, y)
    y0 = kin["k"]
    target = [y0[0] + 0.05, y0[1]]
    run = {"robot": robot, "algorithm": "pseudoinverse", "x0": x0}
    solve = _ok(api.post("/solve", json={**run, "target": target}))
    assert solve["robot"]["units"] == kin["robot"]["units"]
    path = [target, [y0[0] + 0.05, y0[1] + 0.05]]
    rep = _ok(api.post("/repeatability", json={**run, "path": path}))
    assert rep["robot"]["units"] == kin["robot"]["units"]


def test_a_catalogue_arms_solve_says_m_and_rad(api):
    pytest.importorskip("yourdfpy")
    body = _ok(
        api.post(
            "/kinematics", json={"robot": {"name": "panda", "task": "xyz"}, "x": ARMS["panda"].home}
        )
    )
    assert body["robot"]["units"]["x"] == ["rad"] * 7
    assert body["robot"]["units"]["y"] == ["m", "m", "m"]
