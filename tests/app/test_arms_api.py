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
    y0 = _ok(
        api.post(
            "/solve",
            json={
                "robot": robot,
                "algorithm": "pseudoinverse",
                "x0": HOME,
                "target": [0.3, 0.0, 0.6, 0, 0, 0],
            },
        )
    )
    home = np.array(y0["trajectory"]["y"][0])
    return (home + np.array(MOVES)).tolist()


def test_panda_by_name_equals_panda_by_urdf_text(api):
    by_name = {"name": "panda", "task": "pose"}
    by_text = {
        "name": "urdf",
        "urdf": PANDA.urdf,
        "end_link": PANDA.end_link,
        "home": HOME,
        "task": "pose",
    }
    path = _path(api, by_name)
    runs = [
        _ok(
            api.post(
                "/repeatability",
                json={
                    "robot": robot,
                    "algorithm": "pseudoinverse",
                    "x0": HOME,
                    "path": path,
                    "cycles": 2,
                },
            )
        )
        for robot in (by_name, by_text)
    ]
    assert runs[0]["success"] and runs[0]["legs"] == runs[1]["legs"]
    assert runs[0]["drift"] == runs[1]["drift"] and runs[0]["drift"][-1] > 1e-4
    assert (runs[0]["robot"]["p"], runs[0]["robot"]["r"]) == (7, 6)
    assert runs[0]["robot"]["definition"] == by_name


def test_a_pose_target_is_reached(api):
    target = np.array(_path(api, {"name": "panda", "task": "pose"})[1])
    run = _ok(
        api.post(
            "/solve",
            json={
                "robot": {"name": "panda", "task": "pose"},
                "algorithm": "pseudoinverse",
                "x0": HOME,
                "target": target.tolist(),
            },
        )
    )
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
    [
        ({"name": "ur5e", "task": "pose"}, "robot", "6 active joints for a task of 6"),
        ({"name": "panda", "task": "xyzw"}, "robot.task", "coordinates among x y z rx ry rz"),
        ({"name": "panda", "urdf": "<robot/>"}, "robot.urdf", "unknown field"),
        ({"name": "panda", "reference": [0, 0, 0, 2]}, "robot.reference", "norm 1"),
    ],
)
def test_bad_arm_definitions_are_422_naming_the_field(api, robot, field, text):
    r = api.post(
        "/solve",
        json={
            "robot": robot,
            "algorithm": "pseudoinverse",
            "x0": HOME,
            "target": [0.3, 0, 0.6, 0, 0, 0],
        },
    )
    assert r.status_code == 422, r.text
    assert text in r.text and field in r.text, r.text


def test_an_x0_outside_the_limits_is_accepted_and_reported(api):
    x0 = [*HOME[:3], 0.2, *HOME[4:]]  # joint 4's limits: -3.0718, -0.0698
    body = {
        "robot": {"name": "panda", "task": "xyz"},
        "algorithm": "pseudoinverse",
        "x0": x0,
        "path": [[0.45, 0.05, 0.75]],
        "cycles": 1,
    }
    run = _ok(api.post("/repeatability", json=body))
    assert run["success"] and run["limits"]["within"] is False
    assert run["limits"]["violation"] == {
        "cycle": 0,
        "leg": 0,
        "joint": 3,
        "name": "x4 (panda_joint4)",
        "value": 0.2,
        "limit": -0.0698,
        "bound": "upper",
    }


def test_a_solve_reports_its_first_violation_and_the_paper_robots_none(api):
    run = _ok(
        api.post(
            "/solve",
            json={
                "robot": {"name": "panda", "task": "xyz"},
                "algorithm": "pseudoinverse",
                "x0": HOME,
                "target": [-0.3, 0.0, 0.5],
            },
        )
    )
    v = run["limits"]["violation"]
    assert run["converged"] and (v["cycle"], v["leg"], v["joint"], v["bound"]) == (1, 1, 1, "lower")
    ok = _ok(
        api.post(
            "/solve",
            json={
                "robot": {"name": "panda", "task": "xyz"},
                "algorithm": "pseudoinverse",
                "x0": HOME,
                "target": [0.35, 0.05, 0.55],
            },
        )
    )
    assert ok["limits"] == {
        "within": True,
        "violation": None,
        "farthest": None,
        "ends_outside": False,
    }
    m2 = _ok(
        api.post(
            "/solve",
            json={
                "robot": {"name": "manipulator2"},
                "algorithm": "pseudoinverse",
                "x0": [0, 0, 1.5708],
                "target": [0, 2],
            },
        )
    )
    assert "limits" not in m2


def test_a_planar_chain_with_limits_over_rest(api):
    robot = {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1.0, 0.8, 0.6],
        "limits": [[-1, 1], [None, 1.2], [-3, 3]],
    }
    run = _ok(
        api.post(
            "/solve",
            json={
                "robot": robot,
                "algorithm": "pseudoinverse",
                "x0": [0.3, 1.0, 1.0],
                "target": [0.2, 1.2],
            },
        )
    )
    assert run["limits"]["violation"]["name"] == "x2"
    bad = api.post(
        "/solve",
        json={
            "robot": {**robot, "limits": [[1, 0], [0, 1], [0, 1]]},
            "algorithm": "pseudoinverse",
            "x0": [0.3, 1.0, 1.0],
            "target": [0.2, 1.2],
        },
    )
    assert bad.status_code == 422 and "robot.limits" in bad.text and "lower < upper" in bad.text


XYZ = {"robot": {"name": "panda", "task": "xyz"}, "algorithm": "extended", "x0": HOME}
XYZ["target"] = [0.3, 0.1, 0.5]


def test_a_region_of_fewer_joints_than_p_minus_r_is_refused_at_the_region(api):
    """The Panda's position task has p - r = 4: maps h_1..h_4 of x1 and x2 alone make [J; dh]
    singular everywhere, which the region causes, not the start."""
    region = {"x1": [-0.5, 0.5], "x2": [-0.5, 0.5]}
    body = XYZ | {"augmentation": {"name": "e2_synthesized", "region": region}}
    r = api.post("/solve", json=body)
    (error,) = r.json()["detail"]
    assert r.status_code == 422 and error["loc"] == ["body", "augmentation", "region"], r.text
    assert error["msg"].startswith(
        "augmentation.region: must vary at least p - r = 4 of the joints"
    )
    assert "the extended Jacobian [J; dh] of eq. (10) is singular" in error["msg"]


def test_an_arm_without_a_map_for_its_task_is_told_the_map_that_works(api):
    """The Panda (a catalogue arm, with its home) has a default map only for p = r + 1; for the
    position task (p - r = 4) the message gives a map that works, and it does."""
    r = api.post("/solve", json=XYZ)
    (msg,) = [e["msg"] for e in r.json()["detail"]]
    assert msg == (
        "augmentation: the extended inverse needs p - r = 4 augmenting maps, and this panda "
        "(p = 7, r = 3) has a default map only when p = r + 1: ask for 'e2_synthesized' "
        "(E2-optimal over all its joints, +-0.3 around its home; {'name': 'e2_synthesized'} in a "
        "definition or a request) or give {'name': 'formula', 'h': [...]} (4 formulas, one per "
        "degree of redundancy)"
    )
    ok = api.post("/solve", json=XYZ | {"augmentation": {"name": "e2_synthesized"}})
    assert ok.status_code == 200, ok.text
    assert ok.json()["augmentation"]["definition"]["region"].keys() == {
        f"x{i}" for i in range(1, 8)
    }


def test_each_arm_s_schema_says_its_own_default_task():
    """The catalogue arms' request models reuse the URDF robot's field texts; their task's says
    the arm's default (pose; the UR5e's x y z rx ry), not a URDF's (xyz)."""
    from jik.app.compute.schemas.robots import USER_ROBOT_MODELS
    from jik.engine.arms import ARMS

    for arm in ARMS.values():
        model = USER_ROBOT_MODELS[arm.name]
        task = model.model_fields["task"]
        assert task.default == arm.task and task.description.endswith(f"(default {arm.task})")


@pytest.mark.parametrize(
    ("route", "field", "extra"),
    [("/solve", ["target"], {}), ("/repeatability", ["path", 1], {"cycles": 1})],
)
def test_a_rotation_vector_longer_than_pi_is_422_at_once(api, route, field, extra):
    """A pose target the rotation coordinates never take (|r| > pi) is refused as input, with
    the engine's reason, instead of running to the step cap."""
    point = [0.3, 0.0, 0.6, 3.0, 0.0, 1.0]
    key = field[0]
    body = {"robot": {"name": "panda", "task": "pose"}, "algorithm": "pseudoinverse", "x0": HOME}
    body |= extra
    body[key] = point if key == "target" else [[0.3, 0.0, 0.6, 0, 0, 0], point]
    response = api.post(route, json=body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"][0]
    assert detail["loc"][1:] == field  # (the point of a path by its index)
    assert "length 3.16228 > pi" in detail["msg"]
