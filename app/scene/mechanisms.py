"""The scene's mechanisms: the robots' copies (one per algorithm and a grey one at the start x0),
and the task-plane box they span (:func:`extent_of`).

- Manipulator 2 (37): an XY gantry, a beam at height x1 on two rails, a carriage at x2 on the
  beam, and a revolute arm of length l at angle x3; the end effector is the task point.
- Manipulator 1 (30), schematic of its normal form k(x) = (x1, x2 + x1 x3): a slider at height
  x2 on the vertical guide, a lever of slope x3 pivoting on it, and a vertical runner at x1;
  the task point W = (x1, x2 + x1 x3) is where the lever crosses the runner.
- The unicycle (40): a platform with two wheels and a heading nose at the pose q(t).
- A user's planar chain or URDF arm: links as lines between its joints' points, joints as
  spheres, orange outside their limits, and the end link's frame (axes triad: x red, y green,
  z blue) when the task holds its orientation (:class:`Chain`); a formula robot has no
  drawing, only its task path.

One copy per chosen algorithm, in its colour, opacity and height
(:data:`jik.app.dashboard.algorithms.STYLES`: the pseudoinverse the translucent red ghost, the
extended Jacobian the opaque blue robot, as in every plot); the grey ghost is the start x0.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Any, cast

import numpy as np
from viser.transforms import SO3

from ...engine.arms import ARMS
from ...engine.kinematics import Manipulator1
from ...engine.pose_task import COORDINATES
from ..dashboard.joint_limits import outside_joints, state_limits
from ..dashboard.robots import state_kinematics
from ..dashboard.runs import spaced_iterations

#: Manipulator 1's kinematics k(x) = (x1, x2 + x1 x3), eq. (30): where its task point W is.
NORMAL_FORM = Manipulator1()
HOME_COLOR = (150, 150, 150)
#: A joint's colour while its value is outside the robot's limits.
OUTSIDE_COLOR = (255, 140, 0)
#: Length of a target's and of the end link's axes, as a fraction of the arm's reach.
AXES_FRACTION = 0.12


class Mechanism:
    """Scene nodes of one robot copy (one algorithm, or the grey start ghost)."""

    def __init__(self, scene, root: str, color, opacity, z: float, state, extent) -> None:
        self.scene, self.root, self.color, self.opacity, self.z = scene, root, color, opacity, z
        self.state, self.extent = state, extent
        self.build()

    def node(self, kind: str, name: str, color=None, **values):
        """A node of this copy, made by viser's ``add_<kind>``, in its colour (or ``color``) and
        opacity, casting no shadow."""
        add = getattr(self.scene, f"add_{kind}")
        color = color or self.color
        return add(
            f"{self.root}/{name}", color=color, opacity=self.opacity, cast_shadow=False, **values
        )

    def box(self, name, dimensions, position=(0.0, 0.0, 0.0)):
        return self.node("box", name, dimensions=dimensions, position=position)

    def ball(self, name, radius, position=(0.0, 0.0, 0.0), color=None):
        return self.node("icosphere", name, color, radius=radius, position=position, subdivisions=2)

    def build(self) -> None:
        """Create the nodes, those sized by the state or the task-plane box with the values of
        :meth:`fitted`."""

    def fitted(self) -> dict[str, dict[str, Any]]:
        """The values of the nodes that follow the state (an arm length) or the task-plane box,
        by the attribute holding each node: what :meth:`build` creates them with and
        :meth:`resize` sets."""
        return {}

    def resize(self, state, extent) -> None:
        """Follow a new arm length or task-plane box in place (no node is re-created)."""
        self.state, self.extent = state, extent
        for attr, values in self.fitted().items():
            for key, value in values.items():
                setattr(getattr(self, attr), key, value)

    def pose(self, x) -> None: ...


class Gantry(Mechanism):
    """Manipulator 2: XY gantry (prismatic x1 vertical, x2 horizontal) with a revolute arm."""

    def build(self) -> None:
        fit = self.fitted()
        self.beam = self.box("beam", **fit["beam"])
        self.carriage = self.scene.add_frame(f"{self.root}/carriage", show_axes=False)
        self.box("carriage/body", (0.2, 0.2, 0.09))
        self.ball("carriage/joint", 0.06, (0.0, 0.0, 0.07), color=(40, 40, 40))
        self.arm = self.box("carriage/arm", **fit["arm"])
        self.effector = self.ball("carriage/effector", 0.07, **fit["effector"])

    def fitted(self) -> dict[str, dict[str, Any]]:
        """The beam spans the task-plane box in x; the arm is l long."""
        (lo, hi), _ = self.extent
        l = float(self.state.robot_parameters["l"])
        return {
            "beam": {"dimensions": (hi - lo, 0.07, 0.05)},
            "arm": {"dimensions": (l, 0.06, 0.04), "position": (l / 2, 0.0, 0.07)},
            "effector": {"position": (l, 0.0, 0.07)},
        }

    def pose(self, x) -> None:
        (lo, hi), _ = self.extent
        self.beam.position = ((lo + hi) / 2, float(x[0]), self.z)
        self.carriage.position = (float(x[1]), float(x[0]), self.z + 0.05)
        self.carriage.wxyz = SO3.from_z_radians(float(x[2])).wxyz


class NormalForm(Mechanism):
    """Manipulator 1 (30): slider x2 on the vertical guide, lever of slope x3, runner at x1."""

    def build(self) -> None:
        fit = self.fitted()
        self.runner = self.box("runner", **fit["runner"])
        self.slider = self.box("slider", (0.18, 0.14, 0.08))
        self.lever = self.scene.add_frame(f"{self.root}/lever", show_axes=False)
        self.bar = self.box("lever/bar", **fit["bar"])
        self.ball("lever/pivot", 0.06, (0.0, 0.0, 0.05), color=(40, 40, 40))
        self.point = self.ball("W", 0.08)
        chosen = tuple(self.state.algorithms)
        if self.root.endswith("/" + ("extended" if "extended" in chosen else chosen[0])):
            self.scene.add_label(  # (below the point: clear of the start gizmo's label)
                f"{self.root}/W/label", "W (task point)", position=(0.1, -0.2, -0.35)
            )

    def fitted(self) -> dict[str, dict[str, Any]]:
        """The runner spans the task-plane box in y; the lever, from x = xlo to x = xhi of the
        box when level (shorter in x when it tilts, so it stays in the framed view)."""
        (xlo, xhi), (lo, hi) = self.extent
        return {
            "runner": {"dimensions": (0.05, hi - lo, 0.04)},
            "bar": {
                "dimensions": (xhi - xlo, 0.045, 0.03),
                "position": ((xlo + xhi) / 2, 0.0, 0.05),
            },
        }

    def pose(self, x) -> None:
        x1, x2, x3 = (float(v) for v in x)
        _, (lo, hi) = self.extent
        self.runner.position = (x1, (lo + hi) / 2, self.z)
        self.slider.position = (0.0, x2, self.z)
        self.lever.position = (0.0, x2, self.z)
        self.lever.wxyz = SO3.from_z_radians(math.atan(x3)).wxyz
        W = NORMAL_FORM.forward(np.asarray(x, dtype=float))
        self.point.position = (float(W[0]), float(W[1]), self.z + 0.08)


class Platform(Mechanism):
    """The unicycle: a wheeled platform at pose (q1, q2, q3), nose pointing along the heading,
    at half a manipulator's copy's height."""

    def build(self) -> None:
        self.frame = self.scene.add_frame(f"{self.root}/platform", show_axes=False)
        self.box("platform/body", (0.7, 0.45, 0.18), (0.0, 0.0, 0.2))
        self.box("platform/nose", (0.3, 0.12, 0.08), (0.45, 0.0, 0.2))
        axle = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # cylinder axis -> y
        for side in (-1, 1):
            wheel = {"radius": 0.16, "height": 0.08, "position": (0.0, side * 0.28, 0.16)}
            self.node("cylinder", f"platform/wheel{side}", (50, 50, 50), **wheel, wxyz=axle)

    def pose(self, q) -> None:
        self.frame.position = (float(q[0]), float(q[1]), 0.5 * self.z)
        self.frame.wxyz = SO3.from_z_radians(float(q[2])).wxyz


class Chain(Mechanism):
    """A user's serial arm (a planar chain, a URDF arm): its links as lines between the points
    of ``kinematics.points(x)`` (base first, the end last) and its joints as spheres. A planar
    chain lies in the task plane; a URDF arm stands in its own x, y, z."""

    def build(self) -> None:
        self.resize(self.state, self.extent)  # (its kinematics and limits; no node is sized)
        x0 = np.asarray(self.state.x0, dtype=float)
        n = len(self.kin.drawn_points(x0))
        self.links = self.scene.add_line_segments(
            f"{self.root}/links",
            np.zeros((n - 1, 2, 3)),
            self.color,
            thickness=5.0 if self.opacity is None else 3.5,
            thickness_units="screen",
        )
        # Joints sized to the arm: a sixtieth of its reach from its first joint (0.04 for an arm
        # of reach 2.4); the base link is not part of the reach.
        reach = float(np.linalg.norm(np.diff(self.kin.points(x0), axis=0), axis=1).sum())
        ball = max(reach, 1e-3) / 60
        self.joints = [self.ball(f"joint{i}", ball if i < n - 1 else 1.5 * ball) for i in range(n)]
        # The end link's frame when the task gives a whole frame (position and rotation).
        self.end = None
        if set(getattr(self.kin, "task_names", ())) == set(COORDINATES):
            size = AXES_FRACTION * reach
            self.end = self.scene.add_frame(
                f"{self.root}/end", axes_length=size, axes_radius=0.06 * size
            )

    def resize(self, state, extent) -> None:
        """Follow a new state: its kinematics, its joint limits and which drawn joint is each
        variable's (coloured when outside)."""
        super().resize(state, extent)
        self.kin = cast(Any, state_kinematics(state))  # (a PlanarChain or a UrdfChain)
        self.limits, self.at = state_limits(state), self.kin.joint_points
        self.marked: set[int] = set()

    def pose(self, x) -> None:
        pts = chain_points(self.kin, np.asarray(x, dtype=float), self.z + 0.05)
        self.links.points = np.stack([pts[:-1], pts[1:]], axis=1)
        for ball, point in zip(self.joints, pts, strict=False):
            ball.position = tuple(float(v) for v in point)
        if self.end is not None:
            self.end.position, self.end.wxyz = end_frame(self.kin, x)
        outside = {self.at[int(i)] for i in outside_joints(self.limits, x) if int(i) in self.at}
        for k in outside ^ self.marked:  # (only the joints whose colour changes)
            self.joints[k].color = OUTSIDE_COLOR if k in outside else self.color
        self.marked = outside


def chain_points(kin: Any, x: np.ndarray, z: float) -> np.ndarray:
    """The points of a chain (..., m, 3) in the scene, its ``drawn_points`` (PlanarChain,
    UrdfChain): a planar one at height ``z``; an arm in space where it is (its end on its pose
    targets: the copies overlap, red translucent)."""
    pts = np.asarray(kin.drawn_points(x), dtype=float)
    if pts.shape[-1] == 2:
        return np.concatenate([pts, np.full((*pts.shape[:-1], 1), z)], axis=-1)
    return pts


def runs_points(result, kin: Any) -> np.ndarray:
    """The points (n, 3) of a chain in the configurations of ``result``'s runs (about 200 of
    them, evenly spaced), at height 0: what the scene's box and camera must hold."""
    xs = np.concatenate([r.x for r in result.runs.values()])
    return chain_points(kin, xs[:: max(1, len(xs) // 200)], 0.0).reshape(-1, 3)


def wxyz(R) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) of a rotation matrix (3, 3)."""
    q = SO3.from_matrix(np.asarray(R, dtype=float)).wxyz
    return tuple(float(v) for v in q)  # type: ignore[return-value]


def end_frame(kin: Any, x) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(position, wxyz) of a URDF arm's end link at ``x`` (p,)."""
    R, t = kin.end_pose(np.asarray(x, dtype=float))
    return tuple(float(v) for v in t), wxyz(R)


#: The robots drawn as a serial chain of links (:class:`Chain`): a user's and the catalogue's arms.
CHAINS = ("planar_chain", "urdf", *ARMS)
MECHANISMS: dict[str, type[Mechanism]] = dict.fromkeys(CHAINS, Chain)
MECHANISMS.update(manipulator1=NormalForm, manipulator2=Gantry, unicycle=Platform)


def layout_name(state) -> str:
    """The name of a state's set of nodes: its robot, and for a user robot its definition (a
    chain of other links is another set)."""
    if state.robot_definition is None:
        return state.robot
    text = json.dumps(state.robot_definition, sort_keys=True).encode()
    return f"{state.robot}-{hashlib.sha256(text).hexdigest()[:12]}"


def extent_of(result) -> tuple[tuple[float, float], tuple[float, float]]:
    """Box of the task plane used by the mechanisms (rails, runner), covering both runs."""
    runs, robot = result.runs.values(), result.state.robot
    if any(r.platform is not None for r in runs):
        drawn = [r.platform[i] for r in runs for i in spaced_iterations(len(r.platform), 64)]
        ys = np.vstack([*drawn, [result.state.target]])
        lo, hi = ys.min(axis=0)[:2] - 1.0, ys.max(axis=0)[:2] + 1.0
    elif robot in CHAINS:  # (the whole arm, not only its end)
        pts = runs_points(result, state_kinematics(result.state))
        lo, hi = pts.min(axis=0)[:2] - 0.3, pts.max(axis=0)[:2] + 0.3
    elif robot not in MECHANISMS:  # (a formula robot: its paths, of any size)
        ys = np.vstack([*(r.y[:, :2] for r in runs), np.asarray(result.targets)[:, :2]])
        pad = max(0.15 * float(np.max(np.ptp(ys, axis=0))), 1e-3)
        lo, hi = ys.min(axis=0) - pad, ys.max(axis=0) + pad
    else:
        ys = np.concatenate([r.y for r in runs])
        lo = np.minimum(ys.min(axis=0)[:2], 0.0) - 0.6
        hi = np.maximum(ys.max(axis=0)[:2], 1.0) + 0.6
        if robot == "manipulator2":  # (and the carriage's x2)
            x2 = np.concatenate([r.x[:, 1] for r in runs])
            lo[0], hi[0] = min(lo[0], x2.min() - 0.4), max(hi[0], x2.max() + 0.4)
    return (float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))
