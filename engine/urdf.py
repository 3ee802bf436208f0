"""Serial arms from URDF: the chain from the base to an end link, its pose as the task.

The text is read by :mod:`jik.engine.urdf_parse` (yourdfpy, hardened XML, no meshes); forward
kinematics and the Jacobian are computed here, batched over configurations with numpy
(:mod:`jik.engine.serial_chain`), and the task's coordinates, positions and rotation vectors, by
:mod:`jik.engine.pose_task`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .exceptions import InvalidInputError
from .kinematics import Kinematics
from .pose_task import PoseTask, parse_task, reference_rotation, task_text
from .serial_chain import ChainStep, CompiledChain
from .urdf_parse import MAX_URDF_BYTES, mesh_note, parse_urdf
from .validation import MAX_JOINTS, FloatArray, as_vector, json_number

__all__ = ["MAX_URDF_BYTES", "ChainJoint", "UrdfChain", "mesh_note", "parse_urdf"]

MOVABLE = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class ChainJoint:
    """A joint on the chain: its fixed origin (4, 4), unit axis, type and variable.

    ``index`` is the joint's place in x (an active joint), or -1 with ``value`` its locked value.
    """

    name: str
    type: str
    origin: FloatArray
    axis: FloatArray
    index: int
    value: float


def _rotation(axis: FloatArray, q: FloatArray) -> FloatArray:
    """Rotation about the unit ``axis`` by angles q (...,): (..., 3, 3) (Rodrigues)."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    s, c = np.sin(q)[..., None, None], np.cos(q)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


class UrdfChain(Kinematics):
    """The pose of ``end_link`` (or some of its coordinates) as a kinematics, eq. (4).

    Parameters
    ----------
    urdf : str
        URDF text (at most ``MAX_URDF_BYTES``).
    end_link : str
        The link whose origin is the end point; the chain runs from ``base_link`` to it.
    active_joints : sequence of str, optional
        The joints that are the variables x1..xp, in this order; default: every revolute,
        continuous or prismatic joint on the chain, base first.
    task : str or sequence of str
        The end link's coordinates (:func:`~jik.engine.pose_task.parse_task`): ``x y z`` its
        position in the base frame, ``rx ry rz`` the rotation vector log(R0^T R) of its
        orientation; ``"pose"`` for all six, ``"xyz"`` (the default) or any subset.
    locked : mapping str -> float, optional
        Values of the chain's movable joints that are not active (default 0) [rad or m].
    home : sequence of float, optional
        A reference configuration (p values): default the zero configuration clipped into the
        joint limits.
    reference : optional
        R0 as a rotation vector, a quaternion (x y z w) or a matrix
        (:func:`~jik.engine.pose_task.reference_rotation`); default: the end link's orientation
        at ``home``, so that ``home`` has rotation coordinates 0. The rotation coordinates are
        those of the principal log, |phi| <= pi, not differentiable at a half turn from R0
        (:mod:`jik.engine.so3`): keep the task's orientations well within a half turn of R0.
        The base frame (``[0, 0, 0]``) is a half turn from a Panda's home, whose flange points
        down: there k jumps and the solves stall.
    base_link : str, optional
        The link whose frame is the base frame, an ancestor of ``end_link``: default the URDF's
        root. A link above a floating or planar joint (a mobile or humanoid robot's) makes the
        chain start past it: a torso for an arm, a mobile base for its manipulator.

    Notes
    -----
    Forward kinematics composes, joint by joint along the chain, the joint's origin and its
    motion (rotation about, or translation along, its axis). The Jacobian is analytic: the
    geometric Jacobian's column j is (z_j x (p - o_j), z_j) for a revolute joint and (z_j, 0)
    for a prismatic one, with z_j its axis and o_j its origin in the base frame and p the end
    point; the rotation rows map it through the SO(3) log's derivative (:mod:`jik.engine.so3`).
    """

    name = "urdf"
    home: tuple[float, ...]

    def __init__(
        self,
        urdf: str,
        end_link: str | None,
        active_joints: Sequence[str] | None = None,
        task: str | Sequence[str] = "xyz",
        locked: Mapping[str, float] | None = None,
        home: Sequence[float] | None = None,
        reference=None,
        base_link: str | None = None,
    ) -> None:
        model = parse_urdf(urdf)
        self.robot_name = str(model.robot.name)
        links = {link.name for link in model.robot.links}
        if end_link is None:
            raise InvalidInputError(
                f"end_link is required (the name of the end link); links: {sorted(links)}",
                "end_link",
            )
        if not isinstance(end_link, str) or end_link not in links:
            raise InvalidInputError(
                f"end_link {end_link!r} is not a link of the URDF; links: {sorted(links)}",
                "end_link",
            )
        if base_link is not None and (not isinstance(base_link, str) or base_link not in links):
            raise InvalidInputError(
                f"base_link {base_link!r} is not a link of the URDF; links: {sorted(links)}",
                "base_link",
            )
        parent_joint = {j.child: j for j in model.robot.joints}
        chain, link = [], end_link
        while link in parent_joint and link != base_link:
            joint = parent_joint[link]
            chain.append(joint)
            link = joint.parent
            if len(chain) > len(model.robot.joints):
                raise InvalidInputError("urdf: the joints form a loop", "urdf")
        chain.reverse()
        if base_link is not None and link != base_link:
            above = [link, *(j.child for j in chain)]
            raise InvalidInputError(
                f"base_link {base_link!r} is not on the chain from the root to {end_link!r}; "
                f"its links are {above}",
                "base_link",
            )
        self.base_link, self.end_link = link, end_link
        movable = [j.name for j in chain if j.type in MOVABLE]
        for j in chain:
            if j.type not in (*MOVABLE, "fixed"):
                raise InvalidInputError(
                    f"joint {j.name!r} on the chain is {j.type}; only revolute, continuous, "
                    "prismatic and fixed joints are supported (start the chain past it: "
                    f"base_link {j.child!r})",
                    "urdf",
                )
            if j.mimic is not None and j.type in MOVABLE:
                raise InvalidInputError(
                    f"joint {j.name!r} on the chain mimics another; mimic joints are not supported",
                    "urdf",
                )
        if active_joints is not None and (
            isinstance(active_joints, str) or not isinstance(active_joints, Sequence)
        ):
            raise InvalidInputError("active_joints must be a list of joint names", "active_joints")
        active = list(movable if active_joints is None else active_joints)
        for i, name in enumerate(active):
            if name not in movable:
                raise InvalidInputError(
                    f"active_joints[{i}]: {name!r} is not a movable joint on the chain from "
                    f"{self.base_link!r} to {end_link!r}; those are {movable}",
                    f"active_joints.{i}",
                )
        if len(set(active)) != len(active):
            raise InvalidInputError(f"active_joints repeats a joint: {active}", "active_joints")
        if len(active) > MAX_JOINTS:
            raise InvalidInputError(
                f"active_joints: {len(active)} of the {len(movable)} movable joints on the chain "
                f"from {self.base_link!r} to {end_link!r} would be active; at most "
                f"{MAX_JOINTS} can be (name at most that many in active_joints; the others stay "
                "at 0 or at their locked values)",
                "active_joints",
            )
        joint_names = {j.name for j in model.robot.joints}
        if locked is not None and not isinstance(locked, Mapping):
            raise InvalidInputError("locked must map joint names to values", "locked")
        locked = dict(locked or {})
        for name, value in locked.items():
            if name not in joint_names or name in active:
                raise InvalidInputError(
                    f"locked joint {name!r} is not a joint of the URDF, or is active",
                    f"locked.{name}",
                )
            json_number(value, f"locked.{name}")
        names = parse_task(task)
        self.task, self.task_names = task_text(names), names
        self.joint_names = tuple(active)
        self.p, self.r = len(active), len(names)
        if self.p <= self.r:  # (naming what the caller gave: the task, or the active joints)
            raise InvalidInputError(
                f"{self.p} active joints for a task of {self.r} coordinates: a redundant robot "
                "needs more joints than task coordinates",
                "task" if active_joints is None else "active_joints",
            )
        self.variable_names = tuple(f"x{i + 1}" for i in range(self.p))
        self.chain = tuple(
            ChainJoint(
                j.name,
                {"fixed": "fixed", "prismatic": "prismatic"}.get(j.type, "revolute"),
                _origin(j),
                np.array([1.0, 0.0, 0.0]) if j.type == "fixed" else _unit(j.axis, j.name),
                active.index(j.name) if j.name in active else -1,
                float(locked.get(j.name, 0.0)),
            )
            for j in chain
        )
        self.limits = tuple(_limits(model.joint_map[name]) for name in active)
        self.locked = {j.name: j.value for j in self.chain if j.type != "fixed" and j.index < 0}
        self.joint_limits = np.array([_bounds(model.joint_map[name]) for name in active])
        self.compiled = CompiledChain(
            [ChainStep(j.origin, j.axis, j.type, j.index, j.value) for j in self.chain], self.p
        )
        lo, hi = np.array(self.limits).T
        try:
            self.home = tuple(
                np.clip(0.0, lo, hi) if home is None else as_vector(home, self.p, "home")
            )
        except InvalidInputError as exc:
            raise InvalidInputError(str(exc), "home") from None
        self.reference = (
            self.compiled.pose(np.array(self.home))[0]
            if reference is None
            else reference_rotation(reference)
        )
        self.pose_task = PoseTask(names, self.reference)
        self.urdf = urdf
        #: What was skipped while reading the URDF (mesh references), for the run's result.
        self.notes = tuple(n for n in (mesh_note(model),) if n)

    @property
    def parameters(self) -> dict[str, object]:
        return {
            "end_link": self.end_link,
            "active_joints": list(self.joint_names),
            "task": self.task,
            "locked": dict(self.locked),
            "home": list(self.home),
            "reference": self.reference.tolist(),
            "base_link": self.base_link,
        }

    def _described(self) -> dict[str, object]:
        out: dict[str, object] = {
            "robot": self.robot_name,
            "end_link": self.end_link,
            "task": self.task,
        }
        if self.locked:
            out["locked"] = len(self.locked)
        return out

    def frames(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint origins o (..., n, 3), joint axes z (..., n, 3) in the base frame, for the n
        joints of the chain (fixed ones included), and the end link's pose (..., 4, 4)."""
        x = np.asarray(x, dtype=float)
        T = np.broadcast_to(np.eye(4), (*x.shape[:-1], 4, 4))
        origins, axes = [], []
        for j in self.chain:
            T = T @ j.origin
            origins.append(T[..., :3, 3])
            axes.append(T[..., :3, :3] @ j.axis)
            if j.type == "fixed":
                continue
            q = x[..., j.index] if j.index >= 0 else np.full(x.shape[:-1], j.value)
            M = np.broadcast_to(np.eye(4), T.shape).copy()
            if j.type == "revolute":
                M[..., :3, :3] = _rotation(j.axis, q)
            else:
                M[..., :3, 3] = q[..., None] * j.axis
            T = T @ M
        return np.stack(origins, axis=-2), np.stack(axes, axis=-2), T

    def points(self, x: FloatArray) -> FloatArray:
        """Joint origins and the end point, base frame: (..., p) -> (..., n + 1, 3)."""
        o, _, T = self.frames(x)
        return np.concatenate([o, T[..., None, :3, 3]], axis=-2)

    @property
    def base_offset(self) -> bool:
        """Whether the first joint lies away from the base frame's origin (the Panda's stands
        0.333 m above it): that fixed offset, which no joint moves, is the arm's first link."""
        return bool(np.linalg.norm(self.chain[0].origin[:3, 3]) > 1e-9)

    def drawn_points(self, x: FloatArray) -> FloatArray:
        """The arm as a polyline through its links, base frame: (..., p) -> (..., m, 3): the base
        frame's origin when the first joint lies away from it (:attr:`base_offset`), then
        :meth:`points`."""
        pts = self.points(x)
        if not self.base_offset:
            return pts
        return np.concatenate([np.zeros((*pts.shape[:-2], 1, 3)), pts], axis=-2)

    @property
    def joint_points(self) -> dict[int, int]:
        """Which point of :meth:`drawn_points` is each joint variable's joint, by its index in x
        (the chain's joints in order, fixed ones included)."""
        first = int(self.base_offset)
        return {j.index: first + k for k, j in enumerate(self.chain) if j.index >= 0}

    def check_target(self, y, name: str = "target", field: str | None = None) -> FloatArray:
        """:meth:`Kinematics.check_target`: the rotation coordinates' length at most pi
        (:meth:`~jik.engine.pose_task.PoseTask.check_reachable`)."""
        y = self.check_task(y, name, field)
        self.pose_task.check_reachable(y, name, field)
        return y

    def check_start(self, x, name: str = "x0") -> FloatArray:
        """:meth:`Kinematics.check_start`: not on the rotation coordinates' cut
        (:meth:`~jik.engine.pose_task.PoseTask.check_start`)."""
        x = super().check_start(x, name)
        self.pose_task.check_start(self.compiled.pose(x)[0], name)
        return x

    def forward(self, x: FloatArray) -> FloatArray:
        """k(x): the task's coordinates of the end link's pose: (..., p) -> (..., r)."""
        R, t = self.compiled.pose(x)
        return self.pose_task.value(R, t)

    def jacobian(self, x: FloatArray) -> FloatArray:
        """J(x): (..., p) -> (..., r, p), analytic (see the class notes)."""
        return self.pose_task.value_jacobian(*self.compiled.pose_jacobian(x))[1]

    def forward_jacobian(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """k(x) (..., r) and J(x) (..., r, p) from one pass along the chain."""
        return self.pose_task.value_jacobian(*self.compiled.pose_jacobian(x))

    @property
    def scratch(self) -> int:
        """Float64 numbers per configuration of an evaluation of J: the m movable joints'
        4 x 4 transforms and the geometric Jacobian, a few times over."""
        return 48 * (self.compiled.m + 1)

    def end_pose(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The end link's rotation (..., 3, 3) and position (..., 3) in the base frame."""
        return self.compiled.pose(x)


def _unit(axis, name: str) -> FloatArray:
    """The joint's axis normalised (x when the URDF gives none; 3 numbers, :func:`parse_urdf`
    checks): finite, not all 0. It is scaled by its largest component first, so that a norm
    of 1e200-sized or 1e-200-sized numbers neither overflows nor underflows."""
    a = np.array([1.0, 0.0, 0.0]) if axis is None else np.asarray(axis, dtype=float)
    m = float(np.max(np.abs(a)))
    if not (0 < m < np.inf) or not np.all(np.isfinite(a)):
        raise InvalidInputError(f"joint {name!r} has a zero or invalid axis", "urdf")
    return (a / m) / np.linalg.norm(a / m)


def _origin(joint) -> FloatArray:
    """The joint's fixed origin (4, 4): identity when the URDF gives none."""
    origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, dtype=float)
    if not np.all(np.isfinite(origin)):
        raise InvalidInputError(f"joint {joint.name!r} has a NaN or infinite origin", "urdf")
    return origin


def _declared(joint) -> tuple[float, float] | None:
    """The joint's URDF limits [rad or m], or None for a continuous joint or one whose limits
    are missing or empty (lower = upper).

    Raises
    ------
    InvalidInputError
        If a limit is NaN or its lower limit is above its upper one (field ``urdf``, naming
        the joint).
    """
    lim = joint.limit
    if joint.type == "continuous" or lim is None or lim.lower is None or lim.upper is None:
        return None
    lo, hi = float(lim.lower), float(lim.upper)
    if math.isnan(lo) or math.isnan(hi):
        raise InvalidInputError(f"joint {joint.name!r} has a NaN limit", "urdf")
    if lo > hi:
        raise InvalidInputError(
            f"joint {joint.name!r} has its lower limit {lo:g} above its upper limit {hi:g}",
            "urdf",
        )
    return (lo, hi) if lo < hi else None


def _bounds(joint) -> tuple[float, float]:
    """The joint's limits [rad or m]: its URDF limits, unbounded for a continuous joint (or a
    joint whose limits are missing or empty)."""
    return _declared(joint) or (-math.inf, math.inf)


def _limits(joint) -> tuple[float, float]:
    """The joint's range [rad or m], finite: its URDF limits, or (-pi, pi) for a continuous
    joint ((-1, 1) m for a prismatic one without limits); a side declared infinite lies a
    turn (2 m) from the other, and both infinite are as no limits."""
    lo, hi = _bounds(joint)
    width = 2.0 if joint.type == "prismatic" else 2 * math.pi
    if math.isinf(lo) and math.isinf(hi):
        return -width / 2, width / 2
    return (hi - width if math.isinf(lo) else lo), (lo + width if math.isinf(hi) else hi)
