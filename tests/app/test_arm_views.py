"""How the dashboard shows a catalogue arm (the Panda): the scene's camera frames the whole arm
and its pose targets left of viser's control panel, its joints sized to the arm."""

from __future__ import annotations

import math

import numpy as np

from jik.app.dashboard.model import default_state, updated_state
from jik.app.dashboard.results import compute
from jik.app.dashboard.robots import state_kinematics
from jik.app.dashboard.session import Dashboard
from jik.app.scene import DashboardScene
from jik.app.scene.camera import VIEW_DIRECTION, camera_pose, free_fraction, view_of
from jik.app.scene.mechanisms import Chain, chain_points


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


def test_the_camera_frames_the_panda_left_of_the_control_panel():
    """In the reviewer's 722 x 1017 px scene (viser's panel over its right 320 px), every
    joint the Panda's runs pass through and every pose target is in view, left of the panel,
    and the arm fills a good part of that free width (not a few joints close up)."""
    state = _panda()
    result = compute(state)
    center, radius = view_of(result)
    kin = state_kinematics(state)
    xs = np.concatenate([r.x for r in result.runs.values()])
    drawn = chain_points(kin, xs[:: max(1, len(xs) // 200)], 0.0).reshape(-1, 3)
    points = np.vstack([drawn, np.asarray(result.targets)[:, :3]])
    fov, width, height = 1.3, 722.0, 1017.0
    free = free_fraction(width)
    assert free == 1 - 320 / 722 and free_fraction(500.0) == 1.0
    position, look_at = camera_pose(center, radius, fov, width / height, free)
    np.testing.assert_allclose((position - look_at) / np.linalg.norm(position - look_at),
                               VIEW_DIRECTION, atol=1e-12)  # fmt: skip
    u, v = _project(points, position, look_at, fov, width / height)
    edge = -1 + 2 * free  # (the panel's left edge)
    assert u.min() > -1 and u.max() < edge and abs(v).max() < 1, (u.min(), u.max(), v)
    assert u.max() - u.min() > 0.4 * (edge + 1), (u.min(), u.max())  # (not tiny either)


def test_the_panda_joints_are_sized_to_the_arm():
    """A joint's sphere is a sixtieth of the arm's reach: under 2 cm for the Panda (reach
    about 1 m), not 4 cm as for a 2.4 m planar arm."""
    state = _panda()
    dashboard = Dashboard(state)
    scene = DashboardScene(dashboard)
    try:
        arm = Chain(scene.server.scene, "/test/arm", (10, 20, 30), None, 0.0, state,
                    ((-1.0, 1.0), (-1.0, 1.0)))  # fmt: skip
        home = chain_points(arm.kin, np.asarray(state.x0, dtype=float), 0.0)
        reach = float(np.linalg.norm(np.diff(home, axis=0), axis=1).sum())
        assert 0.5 < reach < 1.5
        assert arm.joints[0].radius == reach / 60 < 0.02
        assert arm.joints[-1].radius == 1.5 * reach / 60
    finally:
        scene.stop()
        dashboard.stop()
