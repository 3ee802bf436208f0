"""Poses in the scene: the start point as a draggable gizmo pose and back, and the animation's
timeline (both algorithms' configurations as functions of one playback position)."""

from __future__ import annotations

import math

import numpy as np

from ...engine.kinematics import Manipulator1
from ..dashboard.runs import spaced_iterations

#: Manipulator 1's kinematics k(x) = (x1, x2 + x1 x3), eq. (30): where its task point W is.
NORMAL_FORM = Manipulator1()
#: Unicycle iterations shown in the animation (geometrically spaced, the last always).
UNICYCLE_SHOWN = 10


def gizmo_pose(robot: str, x0, robot_parameters: dict) -> tuple[tuple[float, float], float]:
    """Where the start-point gizmo sits: ((X, Y), yaw) in the task plane.

    Manipulator 2: the carriage (x2, x1), yaw x3. Manipulator 1: the task point
    W = (x1, x2 + x1 x3), yaw atan(x3) (the lever's slope). Unicycle: the initial pose q0.
    """
    if robot == "manipulator2":
        return (x0[1], x0[0]), x0[2]
    if robot == "manipulator1":
        X, Y = (float(v) for v in NORMAL_FORM.forward(np.asarray(x0, dtype=float)))
        return (X, Y), math.atan(x0[2])
    q0 = robot_parameters["q0"]
    return (q0[0], q0[1]), q0[2]


#: Coordinates of a start point from the gizmo that differ from the state's by no more than this
#: keep the state's value: the round trip through the gizmo's pose (a quaternion, a rotation of
#: the axes) is exact only to rounding, and a press on the gizmo must not be a change.
GIZMO_ROUNDING = 1e-9


def _snapped(values, before) -> list[float]:
    pairs = zip(values, map(float, before), strict=True)
    return [b if abs(v - b) <= GIZMO_ROUNDING else v for v, b in pairs]


def start_from_gizmo(robot: str, xy, yaw: float, state) -> dict:
    """The dashboard change for a gizmo moved to ``xy`` with rotation ``yaw`` (inverse of above).

    Manipulator 1 keeps x3 = tan(yaw) within a slope of +-20 (the lever cannot turn vertical).
    Coordinates within :data:`GIZMO_ROUNDING` of the state's keep their value: a gizmo where
    the state puts it gives the state's start point exactly.
    """
    X, Y = float(xy[0]), float(xy[1])
    if robot == "manipulator2":
        x3 = float(state.x0[2]) + math.remainder(yaw - float(state.x0[2]), 2 * math.pi)
        return {"x0": _snapped([Y, X, x3], state.x0)}
    if robot == "manipulator1":
        x3 = math.tan(max(-1.52, min(1.52, yaw)))
        return {"x0": _snapped([X, Y - X * x3, x3], state.x0)}
    q0 = list(state.robot_parameters["q0"])
    q3 = q0[2] + math.remainder(yaw - q0[2], 2 * math.pi)
    return {"robot_parameters": {"q0": _snapped([X, Y, q3], q0)}}


def shown_iterations(result) -> np.ndarray:
    """The unicycle's iterations that the animation and the traces show: :data:`UNICYCLE_SHOWN`
    geometrically spaced ones, the first and the last always."""
    return spaced_iterations(max(len(r.platform) for r in result.runs.values()), UNICYCLE_SHOWN)


class Timeline:
    """Configurations of both algorithms as functions of one playback position s in [0, length]."""

    def __init__(self, result) -> None:
        self.result = result
        self.unicycle = any(r.platform is not None for r in result.runs.values())
        if self.unicycle:
            self.shown = shown_iterations(result)
            self.length = float(len(self.shown))
        else:
            theta_end = max(float(r.theta[-1]) for r in result.runs.values())
            legs = int(max(r.leg.max() for r in result.runs.values())) + 1
            self.leg_theta = theta_end / legs
            self.length = float(legs)

    def at(self, s: float) -> dict[str, np.ndarray]:
        """Per algorithm: the configuration x (manipulators) or pose q (unicycle) at ``s``."""
        s = min(max(s, 0.0), self.length)
        out = {}
        if self.unicycle:
            i = min(int(s), len(self.shown) - 1)
            frac = s - i if s < self.length else 1.0
            for a, run in self.result.runs.items():
                P = run.platform[min(self.shown[i], len(run.platform) - 1)]
                j = frac * (len(P) - 1)
                j0 = min(int(j), len(P) - 2)
                out[a] = P[j0] + (j - j0) * (P[j0 + 1] - P[j0])
            return out
        theta = s * self.leg_theta
        for a, run in self.result.runs.items():
            out[a] = np.array(
                [np.interp(theta, run.theta, run.x[:, k]) for k in range(run.x.shape[1])]
            )
        return out

    def counter(self, s: float) -> str:
        """What the animation shows at ``s``: the unicycle's iteration (of the discrete
        algorithm), or the leg of the closed path (its cycle)."""
        if self.unicycle:
            k = int(self.shown[min(int(s), len(self.shown) - 1)])
            last = max(len(r.platform) for r in self.result.runs.values()) - 1
            return f"**iteration {k}** of {last}"
        legs = max(round(self.length), 1)
        j = min(int(s), legs - 1)
        per = len(self.result.targets)
        cycle = f" (cycle {j // per + 1}, leg {j % per + 1} of {per})" if per < legs else ""
        return f"**leg {j + 1}** of {legs}{cycle}"
