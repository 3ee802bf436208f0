"""POST /kinematics: k(x) and J(x) of any robot, one configuration or a list."""

from __future__ import annotations

import numpy as np
import pytest

from jik.engine.arms import ARMS
from jik.engine.kinematics import Manipulator2
from jik.engine.robot_spec import robot_from_dict

HOME = list(ARMS["panda"].home)


def _ok(response) -> dict:
    assert response.status_code == 200, response.text
    return response.json()


def test_one_configuration_of_a_paper_robot(api):
    x = [0.1, 0.2, 1.3]
    body = _ok(api.post("/kinematics", json={"robot": {"name": "manipulator2", "l": 1.5}, "x": x}))
    kin = Manipulator2(1.5)
    np.testing.assert_allclose(body["k"], kin.forward(np.array(x)), atol=1e-15)
    np.testing.assert_allclose(body["J"], kin.jacobian(np.array(x)), atol=1e-15)
    assert body["variable_names"] == ["x1", "x2", "x3"] and body["task_names"] == ["y1", "y2"]


def test_a_list_of_configurations_of_the_panda_with_its_pose_task(api):
    pytest.importorskip("yourdfpy")
    x = np.random.default_rng(7).uniform(-1, 1, (5, 7))
    x[:, 3] -= 1.5
    body = _ok(
        api.post("/kinematics", json={"robot": {"name": "panda", "task": "pose"}, "x": x.tolist()})
    )
    kin = robot_from_dict({"name": "panda", "task": "pose"}).kinematics
    assert np.shape(body["k"]) == (5, 6) and np.shape(body["J"]) == (5, 6, 7)
    np.testing.assert_allclose(body["k"], kin.forward(x), atol=1e-15)
    np.testing.assert_allclose(body["J"], kin.jacobian(x), atol=1e-15)
    assert body["task_names"] == ["x", "y", "z", "rx", "ry", "rz"]
    home = _ok(
        api.post("/kinematics", json={"robot": {"name": "panda", "task": "pose"}, "x": HOME})
    )
    np.testing.assert_allclose(home["k"], [0.3069, 0, 0.5903, 0, 0, 0], atol=1e-4)


def test_a_user_robot(api):
    robot = {"name": "planar_chain", "joints": "RRP", "lengths": [1.0, 0.5, 0.2]}
    body = _ok(api.post("/kinematics", json={"robot": robot, "x": [0.0, 0.0, 0.1]}))
    np.testing.assert_allclose(body["k"], [1.8, 0.0], atol=1e-15)


def test_where_a_coordinate_is_undefined_so_is_its_row_of_j(api):
    """log(x1) at x1 = -1 has no real value: k's coordinate is null, and so is its row of J
    (its formula's derivative, 1/x1, would be -1); the other row stays."""
    robot = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["log(x1)", "x3"]}
    body = _ok(api.post("/kinematics", json={"robot": robot, "x": [-1.0, 0.0, 0.5]}))
    assert body["k"] == [None, 0.5]
    assert body["J"] == [[None, None, None], [0.0, 0.0, 1.0]]


@pytest.mark.parametrize(
    ("body", "field", "text"),
    [
        ({"robot": {"name": "manipulator2"}, "x": [0.0, 1.0]}, "x", "at least 3 entries"),
        ({"robot": {"name": "panda"}, "x": [[0] * 7, [0] * 6]}, "x", "at least 7 entries"),
        (
            {
                "robot": {"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1]},
                "x": [[0, 0, 0], [0, 1]],
            },
            "x[1]",
            "must have 3 components",
        ),
        (
            {"robot": {"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1]}, "x": [0, 1]},
            "x",
            "must have 3 components (this planar_chain robot has p = 3, r = 2)",
        ),
        ({"robot": {"name": "manipulator2"}, "x": [0, "a", 1]}, "x", ""),
        ({"robot": {"name": "nosuch"}, "x": [0, 0, 0]}, "robot", ""),
        ({"robot": {"name": "manipulator2"}, "x": [[0, 0, 0]] * 1001}, "x", ""),
        ({"robot": {"name": "panda", "task": "xyzq"}, "x": HOME}, "robot.task", ""),
    ],
)
def test_bad_requests_are_422_naming_the_field(api, body, field, text):
    r = api.post("/kinematics", json=body)
    assert r.status_code == 422, r.text
    assert text in r.text
    locs = [".".join(map(str, d["loc"][1:])) for d in r.json()["detail"]]
    assert any(loc.startswith(field.split("[")[0]) for loc in locs), r.text


@pytest.mark.parametrize(
    ("robot", "x", "message"),
    [
        ({"name": "manipulator2"}, [0.0] * 1001, "x: give at most 3 entries, got 1001"),
        ({"name": "manipulator2"}, [], "x: give at least 3 entries, got 0"),
        ({"name": "manipulator2"}, [[0.0] * 3] * 1001, "x: give at most 1000 entries, got 1001"),
        ({"name": "manipulator2"}, [[0.0] * 3, [0.0] * 2], "x[1]: give at least 3 entries, got 2"),
        ({"name": "panda"}, [0.0] * 8, "x: give at most 7 entries, got 8"),
        ({"name": "formula", "variables": ["a"], "task": ["a"]}, [], "x: give at least 1 entry"),
    ],
)
def test_one_or_many_configurations_is_refused_once_for_the_shape_given(api, robot, x, message):
    """x is one configuration or a list of them: a list of numbers is refused as one
    configuration, a list of lists as many, never as both."""
    r = api.post("/kinematics", json={"robot": robot, "x": x})
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["msg"].startswith(message), error
    assert error["loc"] == (["body", "x", 1] if message.startswith("x[1]") else ["body", "x"])


@pytest.mark.parametrize(
    ("reference", "message"),
    [
        ([1.0, 2.0], "robot.reference: give at least 3 entries, got 2"),
        ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], "robot.reference: give at least 3 entries, got 2"),
        ([[1.0, 0.0, 0.0], [0.0, 1.0]] + [[0.0] * 3], "robot.reference[1]: give at least 3"),
        ([0.0] * 5, "robot.reference: give at most 4 entries, got 5"),
    ],
)
def test_an_arms_reference_is_refused_once_for_the_shape_given(api, reference, message):
    """R0 is a rotation vector or quaternion (numbers) or a matrix (rows): one refusal."""
    robot = {"name": "panda", "reference": reference}
    r = api.post("/kinematics", json={"robot": robot, "x": HOME})
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["msg"].startswith(message), error
