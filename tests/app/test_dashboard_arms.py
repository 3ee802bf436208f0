"""A catalogue arm in the dashboard, through the session API: picked by name it is a definition
(its name and task) on the user robots' one path, computed with its synthesized map; the verdict
says whether each run stayed within the joint limits, and the scene colours a joint outside
them. Robots with p - r >= 2 run with a list of formula maps."""

from __future__ import annotations

import json
from unittest.mock import patch

import numpy as np
import pytest

from jik.app.compute.atlas_plan import AtlasLimits, planned
from jik.app.compute.schemas import RobotUsed, UnitsInfo
from jik.app.dashboard.analysis import built_map
from jik.app.dashboard.atlas import atlas_figure, atlas_request
from jik.app.dashboard.controls import controls
from jik.app.dashboard.export import described, export_csv
from jik.app.dashboard.joint_limits import outside_joints, state_limits
from jik.app.dashboard.map_figures import augmenting_spec
from jik.app.dashboard.messages import summary
from jik.app.dashboard.model import default_state, updated_state
from jik.app.dashboard.plotting import units
from jik.app.dashboard.results import compute
from jik.app.dashboard.robots import state_kinematics
from jik.app.dashboard.runs import Cancelled
from jik.app.dashboard.session import Dashboard
from jik.app.dashboard.verdict import verdict
from jik.app.scene import DashboardScene
from jik.app.scene.fixtures import fixtures_of, target_pose
from jik.app.scene.mechanisms import OUTSIDE_COLOR, Chain, end_frame
from jik.engine import robot_from_dict
from jik.engine.arms import ARMS
from jik.engine.atlas_run import run_atlas
from jik.engine.units import robot_units
from tests.app.test_sessions import _computed, _open


def _panda():
    return updated_state(default_state(), {"robot": "panda"})


def test_the_panda_is_picked_by_name_with_its_pose_task(app, client):
    """The picker offers the four arms; the Panda's state is its definition, 7 start
    coordinates within its limits and a closed path of 6-coordinate pose points; both
    algorithms run: the pseudoinverse drifts, the extended inverse (its E2-synthesized map)
    comes back, both within the joint limits, and the verdict says so."""
    options = dict(next(c for c in controls(default_state()) if c.key == "robot").options)
    assert set(ARMS) <= set(options) and options["panda"] == "Franka Panda (arm)"
    session = _open(client)
    r = client.post(f"/api/sessions/{session['id']}/state", json={"robot": "panda"})
    assert r.status_code == 200, r.text
    state = r.json()["state"]
    assert state["robot_definition"] == {"name": "panda", "task": "pose"}
    assert state["augmentation"] == "e2_synthesized"
    assert len(state["x0"]) == 7 and all(len(p) == 6 for p in state["path"])
    _computed(app, session["id"])
    summary = client.get(f"/api/sessions/{session['id']}").json()["summary"]
    assert summary["pseudoinverse"]["drift"][-1] > 1e-5
    assert max(summary["extended"]["drift"]) < 1e-9
    assert summary["extended"]["limits"] == {
        "within": True,
        "violation": None,
        "farthest": None,
        "ends_outside": False,
    }
    again = _open(client, state)  # (the page's link holds the definition)
    assert again["state"] == state
    export = client.get(f"/api/sessions/{session['id']}/export.json").json()
    assert len(export["runs"]["extended"]["x"][0]) == 7
    x0 = [c for c in controls(_panda()) if c.key.startswith("x0.")]
    assert [(c.minimum, c.maximum) for c in x0][3] == (-3.0718, -0.0698)  # its URDF's limits


def test_a_run_outside_the_limits_is_said_in_words_and_marked():
    """x4 = -0.05 is above the Panda's joint 4 upper limit (-0.0698): the start is accepted,
    the verdict names the joint, its value and the limit, and the scene's joint of x4 is the
    one coloured."""
    state = updated_state(_panda(), {"x0.3": -0.05, "task": "target"})
    result = compute(state)
    texts = [s["text"] for s in verdict(result) if s["role"] == "warning"]
    assert any(
        "its start x0 is already outside them, joint x4 (panda_joint4) = -0.05, above "
        "its upper limit -0.0698" in t
        for t in texts
    )
    report = result.limits["pseudoinverse"].as_dict()
    assert report["violation"]["joint"] == 3 and report["violation"]["cycle"] == 0
    kin = state_kinematics(state)
    assert list(outside_joints(state_limits(state), state.x0)) == [3]
    assert kin.joint_points[3] == 4  # (its base link, then x1..x4: no fixed joint before x4)
    assert not len(outside_joints(state_limits(_panda()), _panda().x0))


def test_a_leg_the_long_way_round_the_rotation_coordinates_is_noted():
    """Two orientations 0.08 rad apart on either side of the cut (rz -3.1 and +3.1): the leg
    between them turns the end link by 6.2 rad (a straight line of the coordinates), which the
    verdict says beside the drift, as the engine's findings do."""
    x0 = np.array(_panda().x0)
    x0[6] -= 2.9
    y0 = state_kinematics(_panda()).forward(x0)
    path = [[*y0[:5], -3.1], [*y0[:5], 3.1]]
    state = updated_state(_panda(), {"x0": list(x0), "path": path, "cycles": 1})
    notes = [s["text"] for s in verdict(compute(state)) if s["role"] == "note"]
    assert any(t.startswith("Leg 2 moves the rotation coordinates by 6.2 rad") for t in notes)
    assert not any("Leg" in s["text"] for s in verdict(compute(_panda())))


def test_a_leg_leaving_the_limits_names_its_cycle_and_leg():
    """A planar chain with limits on x2: the path takes x2 past its bound on a leg after the
    start; the violation names that cycle and leg."""
    arm = {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1.0, 0.8, 0.6],
        "limits": [[None, None], [0.3, 0.55], [None, None]],
    }
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": arm})
    result = compute(state)
    violation = result.limits["pseudoinverse"].as_dict()["violation"]
    assert violation is not None and violation["cycle"] >= 1 and violation["leg"] >= 1
    with patch("jik.app.dashboard.joint_limits.legs_report") as legs_report:
        verdict(result), summary(result)  # (the reports built once, by result.limits above)
    legs_report.assert_not_called()
    x = result.runs["pseudoinverse"].x
    first = int(np.flatnonzero((x[:, 1] < 0.3) | (x[:, 1] > 0.55))[0])
    assert violation["value"] == pytest.approx(x[first, 1])


def test_the_scene_draws_pose_targets_as_frames():
    """The targets of a pose task are frames R = R0 exp(phi) at their positions; k(x0) is the
    end link's frame at x0."""
    state = _panda()
    result = compute(state)
    kin = state_kinematics(state)
    fixtures = fixtures_of(result, ((-1.0, 1.0), (-1.0, 1.0)), "/r")
    frames = {k: v for k, v in fixtures.items() if v[0] == "frame"}
    assert len(frames) == len(result.targets) == 4
    home = kin.forward(np.asarray(state.x0))
    position, q = target_pose(kin, home)
    end = end_frame(kin, state.x0)
    np.testing.assert_allclose(position, end[0], atol=1e-12)
    assert abs(abs(np.dot(q, end[1])) - 1.0) < 1e-12  # (the same rotation, q or -q)


def test_vector_maps_run_for_p_minus_r_two():
    """A planar 4R chain with a position task (r = 2) and two formula maps of two components:
    the extended inverse with either is repeatable, the pseudoinverse is not; the h panel says
    what it shows."""
    arm = {
        "name": "planar_chain",
        "joints": "RRRR",
        "lengths": [1.0, 0.8, 0.6, 0.4],
        "augmentations": [
            {"name": "formula", "h": ["x3", "x4"]},
            {"name": "formula", "h": ["x2", "x4"], "label": "other"},
        ],
    }
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": arm})
    for name in ("formula", "other"):
        result = compute(updated_state(state, {"augmentation": name}))
        assert result.runs["pseudoinverse"].drift[-1] > 1e-5
        assert max(result.runs["extended"].drift) < 1e-9
        panel = json.dumps(augmenting_spec(result), ensure_ascii=False).replace("<br>", " ")
        assert "a vector of p − r = 2 maps" in panel and "the h panel draws one map" in panel


def test_the_synthesis_reports_progress_and_a_newer_change_stops_it():
    """The Panda's map is synthesized on first use with its progress on the way; a cancellation
    stops it (nothing kept: the next build synthesizes again from the start)."""
    title = "a Panda of this test"  # (a definition of its own: no map synthesized before)
    state = updated_state(
        default_state(), {"robot": "panda", "robot_definition": {"name": "panda", "title": title}}
    )
    seen: list[float] = []
    with pytest.raises(Cancelled):
        built_map(state, lambda f, what: seen.append(f), lambda: len(seen) >= 2)
    assert len(seen) == 2 and seen[-1] < 1
    seen.clear()  # (it starts over: nothing was kept)
    with pytest.raises(Cancelled):
        built_map(state, lambda f, what: seen.append(f), lambda: len(seen) >= 1)
    assert len(seen) == 1 and seen[0] < 0.5


def test_a_synthesized_vector_map_is_built_with_progress_and_runs():
    """p - r = 2 with ``e2_synthesized``: the vector (h_1, h_2) is synthesized when the state's
    map is built (its progress on the way), and its extended run comes back to x0."""
    box = {"x1": [0.1, 0.5], "x2": [0.4, 0.8], "x3": [0.4, 0.8], "x4": [0.4, 0.8]}
    arm = {
        "name": "planar_chain",
        "joints": "RRRR",
        "lengths": [1, 1, 1, 1],
        "x0": [0.3, 0.6, 0.6, 0.6],
        "title": "a chain of this test (no map synthesized before)",
        "augmentations": [{"name": "e2_synthesized", "region": box}],
    }
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": arm})
    seen: list[float] = []
    built_map(state, lambda f, what: seen.append(f), lambda: False)
    assert seen and seen[-1] == pytest.approx(1.0)
    result = compute(state)
    assert result.runs["pseudoinverse"].drift[-1] > 1e-5
    assert max(result.runs["extended"].drift) < 1e-9


def test_the_atlas_of_an_arm_asks_for_its_definition_and_counts_the_limits():
    """The session's atlas of the Panda is the REST atlas of its definition and its default
    map; the heatmap says how many runs of each algorithm left the joint limits. A user's map
    other than the first is sent as its entry of the definition; the request is made without
    building (synthesizing) the map, which is the atlas workers' to build."""
    with patch("jik.engine.registry.AugmentationSpec.build", side_effect=AssertionError):
        req = atlas_request(_panda(), 16, 2)
    assert req.robot.name == "panda" and req.augmentation is None
    assert len(req.path[0]) == 6 and req.reference == list(_panda().x0)
    drift = [[[1e-4, 2e-4]] * 3]  # (P = 1, N = 3, C = 2)
    result = {
        "algorithms": ["pseudoinverse", "extended"],
        "parameter": [-0.1, 0.0, 0.1],
        "paths": [req.path],
        "drift": {"pseudoinverse": drift, "extended": drift},
        "outside_limits": {"pseudoinverse": 2, "extended": 0},
    }
    units = UnitsInfo(**robot_from_dict({"name": "panda"}).units.summary())
    panda = RobotUsed(name="panda", title="Franka Panda", parameters={}, units=units)
    figure = atlas_figure(result, req, panda)
    assert figure["layout"]["title"]["text"].startswith("Drift after each cycle")
    assert "Franka Panda, γ = " in figure["layout"]["title"]["text"]
    notes = [a["text"] for a in figure["layout"]["annotations"]]
    assert "2 of 3 runs left the joint limits" in notes[0]
    assert "0 of 3 runs left the joint limits" in notes[1]
    arm = {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1.0, 0.8, 0.6],
        "augmentations": [
            {"name": "formula", "h": "x3"},
            {"name": "formula", "h": "x2", "label": "second"},
        ],
    }
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": arm})
    req = atlas_request(updated_state(state, {"augmentation": "second"}), 8)
    assert req.augmentation.h == "x2" and req.robot.name == "planar_chain"


def test_the_scene_colours_a_joint_while_it_is_outside_its_limits():
    """The Panda's copy in the scene: at x4 = -0.05 the joint of x4 takes OUTSIDE_COLOR, the
    others keep the copy's colour; back at home, it is the copy's colour again. Its end link
    carries a frame (the pose task), drawn where it is (on the pose targets)."""
    state = updated_state(_panda(), {"x0.3": -0.05, "task": "target"})
    dashboard = Dashboard(state)
    scene = DashboardScene(dashboard)
    try:
        arm = Chain(
            scene.server.scene,
            "/test/arm",
            (10, 20, 30),
            None,
            0.0,
            state,
            ((-1.0, 1.0), (-1.0, 1.0)),
        )
        arm.pose(state.x0)
        colours = [tuple(ball.color) for ball in arm.joints]
        assert colours[arm.kin.joint_points[3]] == OUTSIDE_COLOR
        assert colours.count(OUTSIDE_COLOR) == 1
        arm.pose(_panda().x0)
        assert all(tuple(ball.color) == (10, 20, 30) for ball in arm.joints)
        # Its end link's frame where the path's pose targets are drawn (k(x0) at home).
        home = arm.kin.forward(np.asarray(_panda().x0))
        assert arm.end is not None
        np.testing.assert_allclose(arm.end.position, home[:3], atol=1e-12)
        np.testing.assert_allclose(arm.joints[-1].position, home[:3], atol=1e-12)
    finally:
        scene.stop()
        dashboard.stop()


def test_the_atlas_of_a_robot_with_two_degrees_of_redundancy():
    """A planar 4R chain with a position task (p - r = 2): its self-motion manifolds are
    surfaces, so the session's atlas gives its starts explicitly, x0 first, all on k(x) = k(x0);
    the pseudoinverse drifts from them, the extended inverse with h = (x3, x4) does not; the
    heatmap numbers the starts."""
    arm = {
        "name": "planar_chain",
        "joints": "RRRR",
        "lengths": [1.0, 0.8, 0.6, 0.4],
        "augmentations": [{"name": "formula", "h": ["x3", "x4"]}],
    }
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": arm})
    req = atlas_request(state, 12, 2)
    X = np.asarray(req.start_points)
    kin = state_kinematics(state)
    assert X.shape == (12, 4) and np.allclose(X[0], state.x0)
    np.testing.assert_allclose(kin.forward(X), kin.forward(X[:1]).repeat(12, 0), atol=1e-12)
    plan, (robot, _) = planned(req, AtlasLimits())
    res = run_atlas(plan)
    drift = {a: res.drift[k] for k, a in enumerate(res.algorithms)}  # (P, N, C)
    assert np.nanmax(drift["extended"]) < 1e-9 and np.nanmin(drift["pseudoinverse"]) > 1e-6
    result = {
        "algorithms": list(res.algorithms),
        "parameter": [],
        "paths": res.paths.tolist(),
        "drift": {a: d.tolist() for a, d in drift.items()},
    }
    figure = atlas_figure(result, req, robot)
    assert list(figure["data"][0]["x"]) == list(range(1, 13))
    assert figure["layout"]["xaxis"]["title"]["text"].startswith("start")


def test_an_arms_units_follow_its_joints_and_task():
    """The Panda's joints are revolute (rad), its pose task in m and rad; a planar RPR chain's
    prismatic joint is in m (the panels' axes and the verdict's norms say so)."""
    result = compute(updated_state(_panda(), {"task": "target"}))
    assert units(result) == (("rad",) * 7, ("m", "m", "m", "rad", "rad", "rad"))
    arm = {"name": "planar_chain", "joints": "RPR", "lengths": [1.0, 0.8, 0.6]}
    kin = state_kinematics(
        updated_state(default_state(), {"robot": "planar_chain", "robot_definition": arm})
    )
    described = robot_units(kin, ("x", "y"))
    assert (described.x, described.y) == (("rad", "m", "rad"), ("m", "m"))


def test_an_arms_export_has_its_rotation_coordinates_in_rad():
    """The export's units are the axes': the Panda's rx ry rz in rad, its x y z in m, and a line
    saying what its lengths are in (a URDF's SI units)."""
    result = compute(updated_state(_panda(), {"task": "target"}))
    units = described(result)["units"]
    assert [units[f"y_{k}"] for k in range(1, 7)] == ["m", "m", "m", "rad", "rad", "rad"]
    assert "# lengths: m: SI units, as in a URDF" in export_csv(result).splitlines()


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_every_catalogue_arm_is_a_dashboard_state(arm):
    """Each arm of the picker gives a state with its definition, its default task's path and a
    synthesized map (the UR5e's default task x y z rx ry: p - r = 1 too)."""
    state = updated_state(default_state(), {"robot": arm})
    assert state.robot_definition == {"name": arm, "task": ARMS[arm].task}
    assert state.augmentation == "e2_synthesized"
    assert len(state.x0) == len(ARMS[arm].home) == len(state.path[0]) + 1


def test_an_arms_position_task_gets_a_map_whose_extended_jacobian_is_regular_at_home():
    """The Panda's xyz task from its home: the last four joints as h would leave joints 1-3 to
    drive x, y, z, and at home joints 1 and 3 move the point the same way ([J; dh] (10)
    singular at x0). The default map keeps four other joints, and the extended Jacobian's run
    goes round the closed path and back to x0."""
    state = updated_state(
        default_state(), {"robot": "panda", "robot_definition": {"name": "panda", "task": "xyz"}}
    )
    result = compute(state)
    assert result.runs["extended"].success, result.runs["extended"].message
    assert np.max(result.runs["extended"].drift) < 1e-8
