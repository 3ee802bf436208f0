"""REST defaults and names of a catalogue arm: the robot's closed path when an atlas gives none,
the map an extended run used (the arm's default, or an e2_synthesized map's default region),
the arm's name in messages, the field of a bad explicit start, and weights of joints whose limits
are too wide to matter."""

from __future__ import annotations

import numpy as np
import pytest

from jik.engine.arms import ARMS
from jik.engine.registry import ROBOTS
from jik.engine.robot_spec import robot_from_dict
from tests.app.conftest import messages
from tests.app.test_atlas_api import wait_until_ended

pytest.importorskip("yourdfpy")
HOME = list(ARMS["panda"].home)
PANDA = {"name": "panda", "task": "pose"}


def _target(task: str = "pose") -> list[float]:
    kin = robot_from_dict({"name": "panda", "task": task}).kinematics
    return (kin.forward(np.array(HOME)) + np.r_[0.05, np.zeros(kin.r - 1)]).tolist()


def _solve(client, **over) -> dict:
    body = {"robot": PANDA, "x0": HOME, "target": _target(), **over}
    r = client.post("/solve", json=body)
    assert r.status_code == 200, r.text
    return r.json()


@pytest.mark.parametrize("robot", [PANDA, {"name": "manipulator2"}])
def test_an_atlas_without_path_runs_the_robot_s_closed_path(api, robot):
    r = api.post("/atlas", json={"robot": robot, "starts": 2, "cycles": 1})
    assert r.status_code == 202, r.text
    done = wait_until_ended(api, r.json()["id"])
    assert done["status"] == "done", done["error"]
    spec = robot_from_dict(robot).spec
    np.testing.assert_allclose(done["result"]["paths"][0], spec.default_path, atol=1e-15)


def test_an_atlas_of_a_robot_without_a_closed_path_asks_for_one(client):
    assert ROBOTS["unicycle"].default_path  # (a curve to follow, not a loop)
    r = client.post("/atlas", json={"robot": {"name": "unicycle"}, "starts": 2})
    (msg,) = messages(r)
    assert msg.startswith("path: unicycle has no default closed path: its default path ")
    assert msg.endswith(
        "is the targets of the paper's experiment, reached once, not a loop: give path"
    )
    assert r.json()["detail"][0]["loc"] == ["body", "path"]


def test_an_extended_run_names_the_map_it_used_and_a_region_defaults_to_the_arm_s(client):
    """Without a map: the arm's E2 synthesis over its box around home (total degree 4), in
    /solve and in /synthesize's 'evaluate'. An e2_synthesized map without a region takes that
    box: the same map, the same run."""
    region = {k: list(v) for k, v in robot_from_dict(PANDA).spec.functional_region.items()}
    default = _solve(client, algorithm="extended")
    assert default["augmentation"]["name"] == "e2_synthesized"
    assert default["augmentation"]["definition"] == {
        "name": "e2_synthesized",
        "region": region,
        "degree": 4,
    }
    given = _solve(client, algorithm="extended", augmentation={"name": "e2_synthesized"})
    assert given["augmentation"] == default["augmentation"] and given["converged"]
    np.testing.assert_allclose(given["x"], default["x"], atol=1e-12)
    other = _solve(
        client, algorithm="extended", augmentation={"name": "e2_synthesized", "degree": 3}
    )
    assert other["augmentation"]["definition"] == {
        **default["augmentation"]["definition"],
        "degree": 3,
    }
    r = client.post("/synthesize", json={"robot": PANDA, "method": "evaluate"})
    assert r.status_code == 200 and r.json()["augmentation"] == default["augmentation"]


def test_messages_name_the_catalogue_arm(client):
    outside = [[-1.0, 1.0]] * 7  # (joint 4 at home, -2.36, is outside)
    r = client.post(
        "/solve",
        json={
            "robot": PANDA,
            "x0": HOME,
            "target": _target(),
            "algorithm": "weighted",
            "algorithm_parameters": {"limits": outside},
        },
    )
    assert r.status_code == 422 and "the weighted inverse of panda is undefined" in r.text
    xyz = {"name": "panda", "task": "xyz"}
    y = _target("xyz")
    r = client.post("/atlas", json={"robot": xyz, "path": [y, y], "starts": 2})
    assert messages(r) == [
        "starts: a self-motion curve needs one degree of redundancy "
        "(p = r + 1); panda has p = 7, r = 3: give start_points"
    ]


def test_a_start_off_the_path_s_first_point_is_named_by_its_index(client):
    y = _target("xyz")
    off = [HOME[0] + 0.1, *HOME[1:]]
    body = {"robot": {"name": "panda", "task": "xyz"}, "path": [y, y], "start_points": [HOME, off]}
    r = client.post("/atlas", json=body)
    body["start_points"] = [off, HOME]
    r0 = client.post("/atlas", json=body)
    assert r.json()["detail"][0]["loc"] == ["body", "start_points", 1]
    assert r0.json()["detail"][0]["loc"] == ["body", "start_points", 0]
    assert messages(r)[0].startswith("start_points[1]: is not on the self-motion manifold")


@pytest.mark.parametrize("width", [1e308, 1.7976931348623157e308])
def test_weighted_with_limits_too_wide_to_matter_is_the_pseudoinverse(client, width):
    plain = _solve(client, algorithm="pseudoinverse")
    wide = _solve(
        client, algorithm="weighted", algorithm_parameters={"limits": [[-width, width]] * 7}
    )
    assert wide["converged"]
    np.testing.assert_allclose(wide["x"], plain["x"], atol=1e-12)


def test_an_e2_map_without_region_of_a_robot_without_a_home_asks_for_one(client):
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 1.0, 1.0]}
    body = {
        "robot": chain,
        "algorithm": "extended",
        "x0": [0.1, 0.5, 0.5],
        "target": [1.5, 1.0],
        "augmentation": {"name": "e2_synthesized"},
    }
    r = client.post("/solve", json=body)
    assert r.json()["detail"][0]["loc"] == ["body", "augmentation", "region"]
    assert "only an arm with a home has a default box" in messages(r)[0]


@pytest.mark.parametrize("robot", [PANDA, {"name": "manipulator2"}])
def test_a_run_without_start_target_or_path_takes_the_robot_s_and_says_so(api, robot):
    """As the command line and /atlas do: the robot's start, target and closed path, echoed in
    the response (x0, target; targets)."""
    spec = robot_from_dict(robot).spec
    body = {"robot": robot, "algorithm": "pseudoinverse"}
    solved = api.post("/solve", json=body)
    assert solved.status_code == 200, solved.text
    out = solved.json()
    assert out["x0"] == list(spec.default_x0) and out["target"] == list(spec.default_target)
    assert out["converged"] and out["trajectory"]["x"][0] == list(spec.default_x0)
    driven = api.post("/repeatability", json={**body, "cycles": 1})
    assert driven.status_code == 200, driven.text
    loop = driven.json()
    assert loop["x0"] == list(spec.default_x0) and loop["success"]
    assert loop["targets"][:3] == spec.default_loop()[:3]


def test_a_robot_without_a_closed_path_needs_one(api):
    """The unicycle's default path is its experiment's targets, not a loop: 422 at path."""
    body = {"robot": {"name": "unicycle"}, "algorithm": "pseudoinverse"}
    r = api.post("/repeatability", json=body)
    assert r.status_code == 422
    assert messages(r)[0].startswith("path: unicycle has no default closed path")
