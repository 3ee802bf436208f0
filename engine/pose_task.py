"""Pose tasks of an arm: the coordinates ``x y z rx ry rz`` of its end link, or a subset.

``x y z`` are the end link's position in the base frame [m]; ``rx ry rz`` the rotation vector
phi = log(R0^T R) [rad] of its orientation R relative to a reference orientation R0
(:mod:`jik.engine.so3`). ``"pose"`` names all six. The Jacobian rows follow from the geometric
Jacobian (Jv, Jw) of the chain: ``dp/dx = Jv`` and ``dphi/dx = Jl^-1(phi) R0^T Jw``.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Sequence

import numpy as np

from . import so3
from .exceptions import InvalidInputError
from .validation import FloatArray, as_points, field_for

COORDINATES = ("x", "y", "z", "rx", "ry", "rz")
_TOKEN = re.compile(r"r[xyz]|[xyz]")


def parse_task(task, field: str = "task") -> tuple[str, ...]:
    """The coordinates of a task: ``"pose"`` (all six), a compact string such as ``"xyz"`` or
    ``"xyzrz"``, pieces separated by spaces or commas (``"x y z rx"``, ``"xz rz"``), or a list
    of names; in the order given, none repeated."""
    names: list[str] = []
    if isinstance(task, str):
        text = task.strip().lower()
        if text == "pose":
            return COORDINATES
        for piece in re.split(r"[\s,]+", text):  # each piece compact: "xyz", "rz", "xyzrz"
            tokens = _TOKEN.findall(piece)
            names += tokens if "".join(tokens) == piece else ["?"]
    elif isinstance(task, Sequence) and all(isinstance(t, str) for t in task):
        names = [t.strip().lower() for t in task]
    if not names or set(names) - set(COORDINATES) or len(set(names)) < len(names):
        raise InvalidInputError(
            f"{field} must be 'pose' or coordinates among x y z rx ry rz, none twice (such as "
            f"'xyz', 'xz' or 'x y z rz'), got {task!r:.80}",
            field,
        )
    return tuple(names)


def task_text(names: Sequence[str]) -> str:
    """The task's canonical text: ``"pose"``, compact positions (``"xz"``), else names."""
    if tuple(names) == COORDINATES:
        return "pose"
    if all(n in "xyz" for n in names):
        return "".join(names)
    return " ".join(names)


def reference_rotation(value, field: str = "reference") -> FloatArray:
    """R0 (3, 3) from a rotation vector (3 numbers, [rad]), a unit quaternion (4 numbers,
    x y z w as ROS and SciPy write it) or a rotation matrix (3 rows of 3)."""
    from scipy.spatial.transform import Rotation

    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = np.zeros(0)
    if not np.all(np.isfinite(a)) or a.shape not in ((3,), (4,), (3, 3)):
        raise InvalidInputError(
            f"{field} must be a rotation vector (3 numbers), a quaternion x y z w (4 numbers) "
            "or a rotation matrix (3 rows of 3)",
            field,
        )
    if a.shape == (3,):
        with np.errstate(all="ignore"):
            R = so3.exp(a)
        if not np.isfinite(R).all():  # (a length whose square overflows: past ~1.3e154)
            raise InvalidInputError(
                f"{field}: a rotation vector must be shorter than 1e154 rad", field
            )
        return R
    if a.shape == (4,):
        if abs(np.linalg.norm(a) - 1.0) > 1e-6:
            raise InvalidInputError(
                f"{field}: a quaternion must have norm 1, got {np.linalg.norm(a):.6g}", field
            )
        return Rotation.from_quat(a).as_matrix()
    if not np.allclose(a.T @ a, np.eye(3), atol=1e-6) or np.linalg.det(a) < 0:
        raise InvalidInputError(
            f"{field}: the matrix is not a rotation (R^T R = I, det R = 1 to 1e-6)", field
        )
    return a


#: How near a half turn from R0 a target or a start is on the rotation coordinates' cut [rad]:
#: far beyond the error of the log there (1e-13), far below an orientation one means to reach.
CUT_MARGIN = 1e-6


#: Why a point on the rotation coordinates' cut is refused, and what to do instead.
ON_THE_CUT = (
    "on the cut of the rotation coordinates, where they jump to the opposite rotation vector "
    "(a run there can end whole turns of the joints away while its task error converges); "
    "choose a reference orientation R0 (the robot's `reference`) within a half turn of the "
    "task's orientations, such as the orientation at the start (a URDF arm's default: at its "
    "home)"
)


class PoseTask:
    """The rows of a pose task: position and rotation coordinates of (R, t) and their Jacobian.

    Parameters
    ----------
    names : sequence of str
        Coordinates among ``x y z rx ry rz`` (:func:`parse_task`).
    reference : (3, 3) array
        R0, the orientation whose rotation coordinates are 0.
    """

    def __init__(self, names: Sequence[str], reference: FloatArray) -> None:
        self.names = tuple(names)
        self.reference = np.asarray(reference, dtype=float)
        self.position_rows = np.array([COORDINATES.index(n) for n in names if len(n) == 1], int)
        self.rotation_rows = np.array([COORDINATES.index(n) - 3 for n in names if len(n) == 2], int)
        # positions then rotations are computed; ``order`` puts them back in the given order
        computed = [n for n in names if len(n) == 1] + [n for n in names if len(n) == 2]
        self.order = np.array([computed.index(n) for n in names])
        self.rotation = self.rotation_rows.size > 0
        #: Where the rotation coordinates sit among the task's coordinates, in its order.
        self.rotation_columns = [i for i, n in enumerate(self.names) if len(n) == 2]
        #: All six in the order x y z rx ry rz: no row is picked or moved.
        self.full = self.names == COORDINATES
        self.reference_T = np.ascontiguousarray(self.reference.T)

    def value(self, R: FloatArray, t: FloatArray) -> FloatArray:
        """k: (..., 3, 3), (..., 3) -> (..., r)."""
        parts = [t[..., self.position_rows]]
        if self.rotation:
            parts.append(so3.log(self.reference_T @ R)[..., self.rotation_rows])
        return np.concatenate(parts, axis=-1)[..., self.order]

    def check_reachable(self, y: FloatArray, name: str, field: str | None = None) -> None:
        """Refuse task points ``y`` (..., r) whose rotation coordinates no configuration gives,
        or that lie on their cut. The rotation coordinates are the principal log of R0^T R
        (:func:`jik.engine.so3.log`), so their length is at most pi (a subset's too); at pi they
        jump to the opposite rotation vector, so a point within :data:`CUT_MARGIN` of it is
        reached from one side and left from the other, and a run toward it turns the wrist by
        whole turns while its error says "converged". The refusal of a point beyond pi gives the
        same orientation within a half turn when the task holds all three and that one is off
        the cut."""
        if not self.rotation:
            return
        r = np.asarray(y, dtype=float)[..., self.rotation_columns]
        length = np.linalg.norm(r, axis=-1)
        far = np.argwhere(length > np.pi - CUT_MARGIN)
        if len(far) == 0:
            return
        at = tuple(int(i) for i in far[0])
        base, where = field_for(name, field), ""
        if length.size > 1:  # (the point, by its index from 0 as a field names it: path[1])
            where = f"[{', '.join(map(str, at))}]"
            base = None if base is None else ".".join([base, *map(str, at)])
        coords = ", ".join(n for n in self.names if len(n) == 2)
        if length[at] <= np.pi + CUT_MARGIN:
            raise InvalidInputError(
                f"{name}{where} is a half turn from the reference orientation R0 (its rotation "
                f"coordinates ({coords}) have length {length[at]:.9g}), {ON_THE_CUT}",
                base,
            )
        same = ""
        # (the principal rotation vector of that rotation, whatever its turns)
        if len(self.rotation_columns) == 3:
            equal = so3.log(so3.exp(r[at]))
            if np.linalg.norm(equal) <= np.pi - CUT_MARGIN:
                same = "; the same orientation is (" + ", ".join(f"{v + 0.0:.6g}" for v in equal)
                same += ")"
        raise InvalidInputError(
            f"{name}{where} is out of reach: its rotation coordinates ({coords}) have length "
            f"{length[at]:.6g} > pi, and the rotation coordinates (the principal log of R0^T R) "
            f"never exceed pi{same}",
            base,
        )

    def check_start(self, R: FloatArray, name: str) -> None:
        """Refuse starts whose end-link orientations R (..., 3, 3) lie on the rotation
        coordinates' cut (a half turn from R0, within :data:`CUT_MARGIN`), where the
        coordinates of k(x0) are either of two opposite rotation vectors."""
        if not self.rotation:
            return
        length = np.linalg.norm(so3.log(self.reference_T @ R), axis=-1)
        near = np.argwhere(length > np.pi - CUT_MARGIN)
        if len(near) == 0:
            return
        at = tuple(int(i) for i in near[0])
        where = f"[{', '.join(map(str, at))}]" if length.size > 1 else ""
        raise InvalidInputError(
            f"{name}{where} puts the end link a half turn from the reference orientation R0 "
            f"({length[at]:.9g} rad), {ON_THE_CUT}",
            name,
        )

    def pose_of(self, y: FloatArray) -> tuple[FloatArray | None, FloatArray | None]:
        """Where task coordinates y (..., r) put the end link, the inverse of :meth:`value` on
        what the task holds: its position t (..., 3) when the task holds x, y and z, its
        orientation R = R0 exp(phi) (..., 3, 3) when it holds rx, ry and rz; None for what the
        task leaves free (a target of eq. (4) then fixes no point or no frame in space)."""
        y = as_points(y, len(self.names), "y")
        at = dict(zip(self.names, np.moveaxis(y, -1, 0), strict=True))
        t, phi = (
            np.stack([at[c] for c in part], axis=-1) if set(part) <= at.keys() else None
            for part in (COORDINATES[:3], COORDINATES[3:])
        )
        return t, None if phi is None else self.reference @ so3.exp(phi)

    def value_jacobian(self, R, t, Jv, Jw) -> tuple[FloatArray, FloatArray]:
        """k (..., r) and J (..., r, p) from the pose and the geometric Jacobian."""
        if self.full and R.ndim == 2:  # one configuration, the whole pose
            phi, L = so3.log_and_jacobian(self.reference_T @ R)
            return np.concatenate((t, phi)), np.concatenate((Jv, (L @ self.reference_T) @ Jw))
        values, rows = [t[..., self.position_rows]], [Jv[..., self.position_rows, :]]
        if self.rotation:
            if R.ndim == 2:
                phi, L = so3.log_and_jacobian(self.reference_T @ R)
            else:
                phi = so3.log(self.reference_T @ R)
                L = so3.left_jacobian_inverse(phi)
            dphi = (L @ self.reference_T) @ Jw
            values.append(phi[..., self.rotation_rows])
            rows.append(dphi[..., self.rotation_rows, :])
        k = np.concatenate(values, axis=-1)[..., self.order]
        J = np.concatenate(rows, axis=-2)[..., self.order, :]
        return k, J


def cut_notes(kinematics, x0, targets) -> list[str]:
    """Sentences on the legs of a path from ``x0`` through ``targets`` (L, r) whose rotation
    coordinates go the long way round: a leg moves along a straight line of the coordinates
    (eq. (5)), so two orientations a little apart on either side of the cut (a half turn from
    R0) are joined by nearly a whole turn of the end link. Empty for a task without all three
    rotation coordinates (what a subset turns by depends on the coordinates left free)."""
    task = getattr(kinematics, "pose_task", None)
    if task is None or task.rotation_rows.size != 3:
        return []
    y = np.vstack([kinematics.forward(np.asarray(x0, dtype=float)), targets])
    r = y[:, task.rotation_columns]
    out = []
    for leg, (a, b) in enumerate(itertools.pairwise(r), start=1):
        along = float(np.linalg.norm(b - a))
        apart = float(np.linalg.norm(so3.log(so3.exp(a).T @ so3.exp(b))))
        if along - apart > np.pi / 2:
            out.append(
                f"Leg {leg} moves the rotation coordinates by {along:.3g} rad between "
                f"orientations {apart:.3g} rad apart: it crosses their cut (a half turn from R0) "
                "the long way round. A reference orientation R0 (`reference`) nearer the path's "
                "orientations makes the leg short."
            )
    return out
