"""Catalogue arms and pose tasks over REST: {"name": "panda", "task": "pose"} equals the same arm
given as URDF text; /robots lists the arms."""

from __future__ import annotations

import numpy as np
import pytest

from jik.engine.arms import ARMS

pytest.importorskip("yourdfpy")
PANDA = ARMS["panda"]
HOME = list(PANDA.home)
#: A closed loop of poses around home: position [m] and rotation vector [rad].
MOVES = [[0.08, 0, 0, 0, 0, 0.2], [0.08, 0.08, 0, 0.15, 0, 0.2], [0, 0.08, -0.04, 0.15, 0, 0]]


def _ok(response) -> dict:
    assert response.status_code == 200, response.text
    return response.json()


def _path(api, robot):
    y0 = _ok(api.post("/solve", json={"robot": robot, "algorithm": "pseudoinverse", "x0": HOME,
                                      "target": [0.3, 0.0, 0.6, 0, 0, 0]}))  # fmt: skip
    home = np.array(y0["trajectory"]["y"][0])
    return (home + np.array(MOVES)).tolist()


def test_panda_by_name_equals_panda_by_urdf_text(api):
    by_name = {"name": "panda", "task": "pose"}
    by_text = {"name": "urdf", "urdf": PANDA.urdf, "end_link": PANDA.end_link, "home": HOME,
               "task": "pose"}  # fmt: skip
    path = _path(api, by_name)
    runs = [
        _ok(api.post("/repeatability", json={"robot": robot, "algorithm": "pseudoinverse",
                                             "x0": HOME, "path": path, "cycles": 2}))
        for robot in (by_name, by_text)
    ]  # fmt: skip
    assert runs[0]["success"] and runs[0]["legs"] == runs[1]["legs"]
    assert runs[0]["drift"] == runs[1]["drift"] and runs[0]["drift"][-1] > 1e-4
    assert (runs[0]["robot"]["p"], runs[0]["robot"]["r"]) == (7, 6)
    assert runs[0]["robot"]["definition"] == by_name


def test_a_pose_target_is_reached(api):
    target = np.array(_path(api, {"name": "panda", "task": "pose"})[1])
    run = _ok(api.post("/solve", json={"robot": {"name": "panda", "task": "pose"},
                                       "algorithm": "pseudoinverse", "x0": HOME,
                                       "target": target.tolist()}))  # fmt: skip
    assert run["converged"] and run["error"] < 1e-9
    np.testing.assert_allclose(run["y"], target, atol=1e-9)


def test_robots_lists_the_arms(api):
    robots = {r["name"]: r for r in _ok(api.get("/robots"))["robots"]}
    for name, arm in ARMS.items():
        info = robots[name]
        assert info["title"] == arm.title and info["default_x0"] == list(arm.home)
        assert info["p"] == len(arm.home) and len(info["task_names"]) == info["r"]
        assert len(info["x_range"]) == info["p"]
    assert robots["panda"]["task_names"] == ["x", "y", "z", "rx", "ry", "rz"]


@pytest.mark.parametrize(
    ("robot", "field", "text"),
    [({"name": "ur5e", "task": "pose"}, "robot", "6 active joints for a task of 6"),
     ({"name": "panda", "task": "xyzw"}, "robot.task", "coordinates among x y z rx ry rz"),
     ({"name": "panda", "urdf": "<robot/>"}, "robot.urdf", "unknown field"),
     ({"name": "panda", "reference": [0, 0, 0, 2]}, "robot.reference", "norm 1")],
)  # fmt: skip
def test_bad_arm_definitions_are_422_naming_the_field(api, robot, field, text):
    r = api.post("/solve", json={"robot": robot, "algorithm": "pseudoinverse", "x0": HOME,
                                 "target": [0.3, 0, 0.6, 0, 0, 0]})  # fmt: skip
    assert r.status_code == 422, r.text
    assert text in r.text and field in r.text, r.text
