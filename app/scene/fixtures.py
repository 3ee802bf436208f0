"""The scene's fixtures: what it draws of a result besides the robots' copies, by node name
(:func:`fixtures_of`): rails or guide, the traces of the computed paths (simplified to what a
pixel shows, in their algorithm's colour) and the targets; and the floor grid.

A URDF arm's task may hold its end link's orientation, ``rx ry rz`` = log(R0^T R)
(:mod:`jik.engine.pose_task`): a target with all three is the frame R = R0 exp(phi) at its
position ``x y z`` (an axes triad: x red, y green, z blue); a target with the position only is a
point; any other (a subset such as ``x z``) is no place in space and is not drawn.

Every line (traces, grid) is sized in pixels: viser's world-unit lines solve a ray-segment
distance per fragment and redraw each line in a second blended pass, for no visible gain at
the dashboard's zoom (frame costs: docs/benchmarks.md, "Dashboard latency").
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from plotly.colors import hex_to_rgb as rgb  # ((r, g, b) of "#rrggbb", as viser takes it)

from ..dashboard.algorithms import COLORS, STYLES
from ..dashboard.robots import state_kinematics
from .mechanisms import AXES_FRACTION, CHAINS, chain_points, wxyz
from .playback import shown_iterations

#: Largest distance of a drawn trace from the computed path, as a fraction of the scene's size
#: (about a third of a pixel at the dashboard's size).
TRACE_TOLERANCE = 1e-3


def simplify(points: np.ndarray, tol: float) -> np.ndarray:
    """The points of the polyline ``points`` (n, d) that keep it within ``tol`` of every
    original point (Ramer-Douglas-Peucker; the first and the last are always kept).

    A trace costs the viser client per segment, on every frame; the continuous task paths are
    straight between targets, eq. (5), so most of their recorded points lie on a line and add
    nothing a pixel shows.
    """
    n = len(points)
    keep = np.zeros(n, dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, n - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, d = points[i], points[j] - points[i]
        rel = points[i + 1 : j] - a
        L2 = float(d @ d)
        t = np.clip(rel @ d / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(rel))
        dist = np.linalg.norm(rel - t[:, None] * d, axis=1)
        k = int(np.argmax(dist))
        if dist[k] > tol:
            m = i + 1 + k
            keep[m] = True
            stack += [(i, m), (m, j)]
    return points[keep]


def polyline(points: np.ndarray, tol: float) -> np.ndarray:
    """(n, 3) points -> segments (m - 1, 2, 3) of the polyline simplified to within ``tol``."""
    points = simplify(points, tol) if tol > 0 and len(points) > 2 else points
    return np.stack([points[:-1], points[1:]], axis=1)


def unicycle_traces(result, root: str, tol: float) -> dict[str, tuple[str, dict, dict]]:
    """The unicycle's paths at its shown iterations
    (:func:`~jik.app.scene.playback.shown_iterations`) as fixtures: each algorithm's the paler
    the earlier, the last in its colour and thicker."""
    shown = shown_iterations(result)
    out: dict[str, tuple[str, dict, dict]] = {}
    for a, run in result.runs.items():
        base = np.asarray(rgb(COLORS[a]), dtype=float)
        for n, i in enumerate(shown):
            P = run.platform[min(int(i), len(run.platform) - 1)]
            last = n == len(shown) - 1
            mix = 1.0 if last else 0.3 + 0.5 * n / len(shown)
            pts = np.column_stack([P[:, 0], P[:, 1], np.full(len(P), 0.02 + STYLES[a].z * 0.2)])
            values = {
                "points": polyline(pts, tol),
                "colors": (255 - mix * (255 - base)).astype(np.uint8),
                "thickness": 3.5 if last else 1.5,
            }
            out[f"{root}/trace/{a}/{n}"] = ("line_segments", values, {"thickness_units": "screen"})
    return out


def target_pose(kin: Any, y) -> tuple[tuple[float, ...], tuple[float, ...] | None] | None:
    """(position, wxyz or None) of a task point ``y`` of a URDF arm: its frame when the task is
    the whole pose, its point when it holds x, y and z
    (:meth:`~jik.engine.pose_task.PoseTask.pose_of`); None otherwise."""
    if getattr(kin, "pose_task", None) is None:
        return None
    t, R = kin.pose_task.pose_of(y)
    if t is None:
        return None
    return tuple(float(v) for v in t), None if R is None else wxyz(R)


def target_fixtures(
    poses, root: str, radius: float, size: float
) -> dict[str, tuple[str, dict, dict]]:
    """The targets of a path's legs as fixtures, one per pose (position, wxyz or None) of
    ``poses`` (None: not drawn, see :func:`target_pose`): a frame (axes triad ``size`` long)
    where it has an orientation, else a ball of ``radius``."""
    out: dict[str, tuple[str, dict, dict]] = {}
    for k, pose in enumerate(poses):
        if pose is None:
            continue
        position, q = pose
        if q is None:
            out[f"{root}/targets/{k}"] = (
                "icosphere",
                {"position": position},
                {"radius": radius, "color": (0, 0, 0)},
            )
        else:
            out[f"{root}/targets/{k}"] = (
                "frame",
                {"position": position, "wxyz": q},
                {
                    "axes_length": size,
                    "axes_radius": 0.06 * size,
                    "origin_radius": 0.12 * size,
                    "origin_color": (0, 0, 0),
                },
            )
    return out


def add_floor_grid(scene) -> None:
    """A grid on the task plane (z slightly below 0), 20 x 20 with cells of 0.5 and section
    lines every 1, drawn as two sets of line segments.

    viser's ``add_grid`` shades every pixel of its plane; line segments draw the same grid at
    the cost of its lines only.
    """
    ticks = 0.5 * np.arange(-20, 21)  # (every other one a section line, from -10 to 10)
    for name, where, color in (
        ("cells", ticks[1::2], (200, 200, 200)),
        ("sections", ticks[::2], (140, 140, 140)),
    ):
        at, span = np.broadcast_arrays(where[:, None], [-10.0, 10.0])  # (n, 2)
        z = np.full(at.shape, -0.06)
        lines = np.concatenate([np.stack([at, span, z], -1), np.stack([span, at, z], -1)])
        scene.add_line_segments(  # (along y at x = where, then along x at y = where)
            f"/grid/{name}", lines, color, thickness=1.0, thickness_units="screen"
        )


def fixtures_of(result, extent, root: str) -> dict[str, tuple[str, dict, dict]]:
    """The parts of a robot's scene besides the mechanisms, by node name: (kind, the values
    that follow the result, the fixed style), made by viser's ``add_<kind>``. The rails
    (Manipulator 2) or the guide (Manipulator 1) span the task-plane box; the task paths of both
    algorithms, and for Manipulator 2 the carriage paths (x2, x1), which are the joint paths:
    closed for J^E#, not for J^P#; the targets of the path's legs. The unicycle's: its paths
    (:func:`unicycle_traces`)."""
    (xlo, xhi), (ylo, yhi) = extent
    span = max(xhi - xlo, yhi - ylo)
    tol = TRACE_TOLERANCE * span
    if result.state.robot == "unicycle":
        return unicycle_traces(result, root, tol)
    # Heights and balls at the manipulators' scale, smaller in a smaller scene (a formula
    # robot's paths may span a few millimetres).
    scale = min(1.0, span / 2.0)
    robot = result.state.robot
    out: dict[str, tuple[str, dict, dict]] = {}
    rails = {
        "manipulator2": {"rails/left": xlo, "rails/right": xhi},
        "manipulator1": {"guide": 0.0},
    }
    for name, x in rails.get(robot, {}).items():  # (grey boxes along y, at x)
        rail = {"dimensions": (0.06, yhi - ylo, 0.05), "position": (x, (ylo + yhi) / 2, -0.02)}
        out[f"{root}/{name}"] = ("box", rail, {"color": (90, 90, 90)})
    chain = robot in CHAINS
    kin = state_kinematics(result.state) if chain else None
    for a, run in result.runs.items():
        line = {"colors": rgb(COLORS[a]), "thickness_units": "screen"}  # pixels, see above
        if chain:  # (the end point's path: a URDF arm's task may be some of x, y, z)
            task = chain_points(kin, run.x, (STYLES[a].z + 0.16) * scale)[:, -1]
        else:
            z = np.full(len(run.y), (STYLES[a].z + 0.16) * scale)
            task = np.column_stack([run.y[:, 0], run.y[:, 1], z])
        out[f"{root}/trace/{a}/task"] = (
            "line_segments",
            {"points": polyline(task, tol)},
            {**line, "thickness": 3.0 if a == "pseudoinverse" else 2.0},
        )
        if robot == "manipulator2":
            joints = np.column_stack(
                [run.x[:, 1], run.x[:, 0], np.full(len(run.x), STYLES[a].z + 0.1)]
            )
            out[f"{root}/trace/{a}/joints"] = (
                "line_segments",
                {"points": polyline(joints, tol)},
                {**line, "thickness": 1.2},
            )
    size = 0.0  # (of a target's axes)
    if chain and robot != "planar_chain":  # (a frame or a point, see target_pose)
        size = AXES_FRACTION * math.hypot(xhi - xlo, yhi - ylo) / 2
        poses, radius = [target_pose(kin, t) for t in result.targets], 0.15 * size
    else:
        poses = [((float(t[0]), float(t[1]), 0.2 * scale), None) for t in result.targets]
        radius = 0.05 * scale
    return {**out, **target_fixtures(poses, root, radius, size)}
