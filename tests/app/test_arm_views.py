"""How the dashboard shows a catalogue arm (the Panda): the scene's camera frames the whole arm
and its pose targets on viser's canvas beside its control panel, its joints sized to the arm;
the task panel shows a pose task's position and orientation, its targets' letters apart; the
E1/E2 panel shows E2 of a 7-joint map beside E2 of each single joint."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import plotly.graph_objects as go
import pytest

from jik.app.dashboard.algorithms import LABELS
from jik.app.dashboard.figures import figure_specs, gamma_free_panels
from jik.app.dashboard.model import default_state, updated_state
from jik.app.dashboard.results import compute
from jik.app.dashboard.robots import state_kinematics
from jik.app.dashboard.session import Dashboard
from jik.app.scene import DashboardScene
from jik.app.scene.camera import (
    INITIAL_ASPECT,
    PANEL_PX,
    VIEW_DIRECTION,
    camera_pose,
    settled_aspect,
    view_of,
)
from jik.app.scene.mechanisms import Chain, chain_points
from jik.engine.urdf import UrdfChain


def _panda():
    return updated_state(default_state(), {"robot": "panda"})


def _project(points, position, look_at, fov, aspect):
    """Normalized image coordinates (u, v in [-1, 1] on screen) of ``points`` (m, 3) seen from
    a camera at ``position`` looking at ``look_at`` with z up."""
    forward = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = points - position
    depth = rel @ forward
    t = math.tan(fov / 2)
    return (rel @ right) / depth / (t * aspect), (rel @ up) / depth / t


def test_the_camera_frames_the_whole_panda_on_the_settled_canvas():
    """The reviewer's page (a 722 x 1014 px scene frame): viser reports its canvas 719 px wide
    at first, 415 px once its control panel is laid out beside it (the vertical field of view
    kept). Framed on the first report, every joint the Panda's runs pass through and every pose
    target is in view on the 415 px canvas, and the arm fills a good part of it (not a few
    joints close up); so does the initial camera, for a client that reported nothing yet."""
    state = _panda()
    result = compute(state)
    center, radius = view_of(result)
    kin = state_kinematics(state)
    xs = np.concatenate([r.x for r in result.runs.values()])
    drawn = chain_points(kin, xs[:: max(1, len(xs) // 200)], 0.0).reshape(-1, 3)
    points = np.vstack([drawn, np.asarray(result.targets)[:, :3]])
    fov, height = 1.309, 1014.0
    assert settled_aspect(719.0, height) == (719.0 - PANEL_PX) / height
    assert settled_aspect(500.0, height) == 500.0 / height  # (too narrow to hold the panel)
    for aspect in (settled_aspect(719.0, height), INITIAL_ASPECT):
        position, look_at = camera_pose(center, radius, fov, aspect)
        direction = (position - look_at) / np.linalg.norm(position - look_at)
        np.testing.assert_allclose(direction, VIEW_DIRECTION, atol=1e-12)
        u, v = _project(points, position, look_at, fov, 415.0 / height)
        assert abs(u).max() < 1 and abs(v).max() < 1, (u, v)
        assert np.ptp(u) > 0.75, np.ptp(u)  # (not tiny either: most of the canvas's width)


def test_the_panda_joints_are_sized_to_the_arm():
    """A joint's sphere is a sixtieth of the arm's reach: under 2 cm for the Panda (reach
    about 1 m), not 4 cm as for a 2.4 m planar arm."""
    state = _panda()
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
        home = arm.kin.points(np.asarray(state.x0, dtype=float))  # (from its first joint)
        reach = float(np.linalg.norm(np.diff(home, axis=0), axis=1).sum())
        assert 0.5 < reach < 1.5
        assert arm.joints[0].radius == reach / 60 < 0.02
        assert arm.joints[-1].radius == 1.5 * reach / 60
    finally:
        scene.stop()
        dashboard.stop()


def test_the_pandas_drawn_chain_starts_at_its_base():
    """The Panda's first joint stands 0.333 m above its base frame's origin: the scene draws
    that base link (the origin first, then the joints), and each joint variable's ball is the
    one after it. An arm whose first joint is at the origin gets no zero-length link."""
    kin = state_kinematics(_panda())
    pts = chain_points(kin, np.zeros(kin.p), 0.0)
    np.testing.assert_allclose(pts[:2], [[0, 0, 0], [0, 0, 0.333]], atol=1e-12)
    assert len(pts) == len(kin.points(np.zeros(kin.p))) + 1
    assert kin.joint_points[0] == 1
    text = (Path(__file__).parents[1] / "data" / "arm4.urdf").read_text()
    at_origin = UrdfChain(text.replace('<origin xyz="0 0 0.05"/>', "<origin/>", 1), "tool")
    assert not at_origin.base_offset
    np.testing.assert_allclose(chain_points(at_origin, np.zeros(4), 0.0)[0], 0, atol=1e-15)
    assert at_origin.joint_points[0] == 0


ALL_FIVE = ["pseudoinverse", "extended", "damped", "weighted", "posture"]


def _title_lines(spec) -> list[str]:
    text = spec["layout"]["title"]["text"]
    return [line.replace("<sup>", "").replace("</sup>", "") for line in text.split("<br>")]


def test_a_pose_task_shows_position_and_rotation_against_theta():
    """The Panda's pose task: one row per coordinate (x y z above rx ry rz) against theta; the
    default loop's turn of +-0.15 rad about z shows on the rz row; every target is marked at
    the end of its leg (letters above the top row, each at its own theta: none overlap).
    The panel depends on theta, so it is not among the gamma-free panels."""
    result = compute(_panda())
    spec = figure_specs(result, only={"task"})["task"]
    go.Figure(spec)  # (valid for plotly: go.Figure validates a dict)
    layout = spec["layout"]
    titles = [layout["yaxis" if k == 0 else f"yaxis{k + 1}"]["title"]["text"] for k in range(6)]
    assert titles == ["x [m]", "y [m]", "z [m]", "rx [rad]", "ry [rad]", "rz [rad]"]
    rz = [
        t
        for t in spec["data"]
        if t.get("yaxis") == "y6"
        and t["name"] in ("pseudoinverse J^P# (8)", "extended Jacobian J^E# (11)")
    ]
    assert rz and all(np.ptp(t["y"]) > 0.29 for t in rz)
    targets = [t for t in spec["data"] if t["name"] == "targets"]
    assert len(targets) == 6 and all(t["mode"] == "markers" for t in targets)
    letters = layout["annotations"]  # (above the top row, each at its leg's end)
    assert all(a["yref"] == "y domain" and a["y"] == 1.0 for a in letters)
    theta = np.asarray([a["x"] for a in letters])
    np.testing.assert_array_equal(theta, targets[0]["x"])
    span = np.ptp(np.concatenate([r.theta for r in result.runs.values()]))
    assert len(theta) == 12 and np.min(np.diff(theta)) > 0.05 * span
    assert [a["text"] for a in letters[:4]] == ["B", "C", "D", "A"]
    # rx, ry stay 0 up to rounding: their axes span +-0.01 rad, not the rounding errors.
    assert all(np.ptp(layout[f"yaxis{k}"]["range"]) >= 0.02 for k in (4, 5))
    np.testing.assert_allclose(targets[5]["y"][:4], np.asarray(result.targets)[:, 5])
    assert "task" not in gamma_free_panels(result)
    # A legend (a saved panel's) names each algorithm, the targets and the start once.
    named = [t["name"] for t in spec["data"] if t.get("showlegend", True)]
    assert sorted(named) == sorted([*(LABELS[a] for a in result.runs), "targets", "start k(x0)"])


def test_the_task_panels_subtitle_wraps_with_five_algorithms():
    """With five algorithms the key of the line styles takes two lines (three, then two) and
    the marks a third: no line of the title is longer than the first's."""
    for state in (default_state(), _panda()):
        result = compute(updated_state(state, {"algorithms": ALL_FIVE}))
        lines = _title_lines(figure_specs(result, only={"task"})["task"])
        assert len(lines) == 4, lines
        assert lines[1].count(":") == 3 and lines[2].count(":") == 2, lines
        assert max(len(line) for line in lines[1:]) <= 70, lines


def _second_phase(result, cancelled=lambda: False):
    from jik.app.dashboard.analysis import kinematics_and_map
    from jik.app.dashboard.second_phase import SecondPhase

    kin, amap = kinematics_and_map(result.state)
    deferred = result.augmenting is None
    return SecondPhase(
        kin,
        amap,
        result,
        deferred=deferred,
        cached=None,
        grid_before=None,
        progress=lambda f, w: None,
        cancelled=cancelled,
    )


def test_the_e1_e2_panel_shows_e2_of_a_7_joint_map_beside_single_joints():
    """The Panda's synthesized map (7 joints, p - r = 1): the second phase takes its E2 by the
    synthesis's Sobol rule (its independent check rule: docs/e2-vector.md), with E2 of
    h = s x_j for each joint, and E1 on the same nodes; the E1/E2 panel draws them as bars (the
    map outlined, first), its title and the h panel's say E1; a cancelled phase raises
    Cancelled."""
    from jik.app.dashboard.runs import Cancelled
    from jik.app.dashboard.second_phase import FUNCTIONALS, GRID

    result = compute(_panda())
    phase = _second_phase(result)
    assert phase.steps == {GRID: 0, FUNCTIONALS: 2}  # (E1, E2 by a rule; no sweep over 7 joints)
    functionals, sens = phase.run()
    assert phase.fraction == 1.0
    assert 2.3e-3 < functionals["E1"] < 2.4e-3 and 1.6e-4 < functionals["E2"] < 1.8e-4
    single = functionals["E2_single_joint"]
    assert set(single) == {f"x{i}" for i in range(1, 8)}
    assert single["x1"]["e2"] == pytest.approx(1.78e-3, rel=1e-2)  # (the docs' table)
    assert min(v["e2"] for v in single.values()) > 5 * functionals["E2"]
    assert sens["kind"] == "single_joint" and len(sens["maps"]) == 8
    specs = figure_specs(result, functionals, {"augmenting", "sensitivity"}, sensitivity=sens)
    bars = specs["sensitivity"]["data"][0]
    go.Figure(specs["sensitivity"])  # (validated)
    assert bars["type"] == "bar" and bars["x"][0] == "h (current)" and bars["x"][1] == "h = +x1"
    assert (
        bars["y"][0] == functionals["E2"]
        and specs["sensitivity"]["layout"]["yaxis"]["type"] == "log"
    )
    low = specs["sensitivity"]["layout"]["yaxis"]["range"][0]
    assert low <= np.log10(functionals["E2"]) - 1  # (the map's bar stands out of the axis)
    # (± the Sobol rule's error estimate: its difference from the rule's first half of the nodes)
    assert functionals["E1_error_estimate"] == pytest.approx(1.5e-6, rel=0.05)
    assert functionals["E2_error_estimate"] == pytest.approx(1.3e-7, rel=0.05)
    pm = "E1 = 0.002346 ± 1e-06, E2 = 0.0001731 ± 1e-07"
    assert pm in specs["augmenting"]["layout"]["title"]["text"]
    pm = "E1 (13) of h = 0.002346 ± 1e-06, E2 = 0.0001731 ± 1e-07"
    assert pm in specs["sensitivity"]["layout"]["title"]["text"]
    with pytest.raises(Cancelled):
        _second_phase(compute(_panda()), cancelled=iter([False] * 3 + [True] * 99).__next__).run()
