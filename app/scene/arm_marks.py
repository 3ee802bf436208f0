"""What the scene draws of a serial arm beyond its links: the pose frames of its task's targets
and of its end link (axes triads: x red, y green, z blue), and its joints outside their limits.

A URDF arm's task may hold its end link's orientation, ``rx ry rz`` = log(R0^T R)
(:mod:`jik.engine.pose_task`): a target with all three is the frame R = R0 exp(phi) at its
position ``x y z``; a target with the position only is a point; any other (a subset such as
``x z``) is no place in space and is not drawn.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import viser.transforms as vtf

from ...engine.pose_task import COORDINATES

#: A joint's colour while its value is outside the robot's limits.
OUTSIDE_COLOR = (255, 140, 0)
#: Length of a target's and of the end link's axes, as a fraction of the arm's reach.
AXES_FRACTION = 0.12


def wxyz(R) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) of a rotation matrix (3, 3)."""
    q = vtf.SO3.from_matrix(np.asarray(R, dtype=float)).wxyz
    return tuple(float(v) for v in q)  # type: ignore[return-value]


def has_pose(kin: Any) -> bool:
    """Whether the task gives a whole frame: position and the three rotation coordinates."""
    return set(getattr(kin, "task_names", ())) == set(COORDINATES)


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
    """The targets of a path's legs as fixtures (:func:`~jik.app.scene.mechanisms.fixtures_of`),
    one per pose (position, wxyz or None) of ``poses`` (None: not drawn, see
    :func:`target_pose`): a frame (axes triad ``size`` long) where it has an orientation, else
    a ball of ``radius``."""
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


def end_frame(kin: Any, x) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(position, wxyz) of a URDF arm's end link at ``x`` (p,)."""
    R, t = kin.end_pose(np.asarray(x, dtype=float))
    return tuple(float(v) for v in t), wxyz(R)
