"""Serial arms from URDF: the chain from the base to an end link, its end position as the task.

yourdfpy (a maintained URDF library; viser's URDF support builds on it) only parses the text;
forward kinematics and the Jacobian are computed here, batched over configurations with numpy.
It is imported when a URDF robot is built, so the rest of the engine works without it
(``pip install 'jik-lab[urdf]'``).

Safety: the text is bounded in size, a document type declaration (the door to XML entity
expansion and external entities) is refused before parsing, meshes are never loaded, and a
mesh file name must stay inside the robot's package (no absolute path, no '..', no URL other
than ``package://``).
"""

from __future__ import annotations

import io
import logging
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import PurePosixPath

import numpy as np

from jik.engine.exceptions import InvalidInputError
from jik.engine.kinematics import Kinematics
from jik.engine.validation import FloatArray, json_number

#: Largest URDF text accepted [bytes].
MAX_URDF_BYTES = 1_000_000
MOVABLE = ("revolute", "continuous", "prismatic")


def _yourdfpy():
    try:
        import yourdfpy
    except ImportError:  # the `urdf` extra is not installed
        raise InvalidInputError(
            "URDF robots need the yourdfpy package: pip install 'jik-lab[urdf]'", "urdf"
        ) from None
    # yourdfpy logs each text it cannot parse as an ERROR ("Using different parsing approach."),
    # which a server printed for every bad URDF a user sent: parse_urdf reports it, in words
    # naming the field, to whoever sent it.
    logging.getLogger("yourdfpy").setLevel(logging.CRITICAL)
    return yourdfpy


def check_mesh_filename(name: str, field: str = "urdf") -> str:
    """A mesh file name that stays inside the robot's package: relative or ``package://``."""
    path = name[len("package://") :] if name.startswith("package://") else name
    parts = PurePosixPath(path).parts
    if (
        not path
        or "\\" in path
        or re.match(r"^[A-Za-z][A-Za-z0-9+.-]*:", path)
        or path.startswith("/")
        or ".." in parts
    ):
        raise InvalidInputError(
            f"{field}: mesh file {name!r} escapes the robot's folder; use a relative path or "
            "package://name/relative/path without '..'",
            field,
        )
    return name


def parse_urdf(text, field: str = "urdf"):
    """Parse URDF text with yourdfpy (no meshes loaded); a ``yourdfpy.URDF``.

    Raises
    ------
    InvalidInputError
        Not a string, over ``MAX_URDF_BYTES``, a DOCTYPE, not a URDF, or a mesh path that
        escapes (:func:`check_mesh_filename`); the message names ``field``.
    """
    if not isinstance(text, str) or not text.strip():
        raise InvalidInputError(f"{field} must be the text of a URDF file", field)
    data = text.encode("utf-8")
    if len(data) > MAX_URDF_BYTES:
        raise InvalidInputError(
            f"{field}: URDF too large ({len(data)} bytes; at most {MAX_URDF_BYTES})", field
        )
    if re.search(rb"<!\s*(DOCTYPE|ENTITY)", data, re.IGNORECASE):
        raise InvalidInputError(f"{field}: a URDF with a DOCTYPE or ENTITY is refused", field)
    yourdfpy = _yourdfpy()
    try:
        model = yourdfpy.URDF.load(
            io.BytesIO(data), build_scene_graph=False, load_meshes=False,
            build_collision_scene_graph=False, load_collision_meshes=False,
        )  # fmt: skip
    except Exception as exc:  # yourdfpy raises whatever its XML walk meets
        raise InvalidInputError(f"{field}: not a valid URDF ({exc})", field) from None
    if model.robot is None or not model.robot.links:
        raise InvalidInputError(f"{field}: the URDF has no links", field)
    for link in model.robot.links:
        for geometry in [v.geometry for v in (*link.visuals, *link.collisions)]:
            if geometry is not None and geometry.mesh is not None:
                check_mesh_filename(str(geometry.mesh.filename), field)
    return model


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
    """The position of ``end_link`` (or some of its coordinates) as a kinematics, eq. (4).

    Parameters
    ----------
    urdf : str
        URDF text (at most ``MAX_URDF_BYTES``).
    end_link : str
        The link whose origin is the end point; the chain runs from the root link to it.
    active_joints : sequence of str, optional
        The joints that are the variables x1..xp, in this order; default: every revolute,
        continuous or prismatic joint on the chain, base first.
    task : str
        The end position's coordinates in the base frame, ``"xyz"`` or a subset such as ``"xz"``.
    locked : mapping str -> float, optional
        Values of the chain's movable joints that are not active (default 0) [rad or m].

    Notes
    -----
    Forward kinematics composes, joint by joint along the chain, the joint's origin and its
    motion (rotation about, or translation along, its axis). The Jacobian is analytic: column j
    is z_j x (p - o_j) for a revolute joint and z_j for a prismatic one, with z_j its axis and
    o_j its origin in the base frame and p the end point.
    """

    name = "urdf"

    def __init__(
        self,
        urdf: str,
        end_link: str,
        active_joints: Sequence[str] | None = None,
        task: str = "xyz",
        locked: Mapping[str, float] | None = None,
    ) -> None:
        model = parse_urdf(urdf)
        self.robot_name = str(model.robot.name)
        links = {link.name for link in model.robot.links}
        if not isinstance(end_link, str) or end_link not in links:
            raise InvalidInputError(
                f"end_link {end_link!r} is not a link of the URDF; links: {sorted(links)}",
                "end_link",
            )
        parent_joint = {j.child: j for j in model.robot.joints}
        chain, link = [], end_link
        while link in parent_joint:
            joint = parent_joint[link]
            chain.append(joint)
            link = joint.parent
            if len(chain) > len(model.robot.joints):
                raise InvalidInputError("urdf: the joints form a loop", "urdf")
        chain.reverse()
        self.base_link, self.end_link = link, end_link
        movable = [j.name for j in chain if j.type in MOVABLE]
        for j in chain:
            if j.type not in (*MOVABLE, "fixed"):
                raise InvalidInputError(f"joint {j.name!r} on the chain is {j.type}; only "
                                        "revolute, continuous, prismatic and fixed joints are "
                                        "supported", "urdf")  # fmt: skip
            if j.mimic is not None and j.type in MOVABLE:
                raise InvalidInputError(f"joint {j.name!r} on the chain mimics another; mimic "
                                        "joints are not supported", "urdf")  # fmt: skip
        if active_joints is not None and (
            isinstance(active_joints, str) or not isinstance(active_joints, Sequence)
        ):
            raise InvalidInputError("active_joints must be a list of joint names", "active_joints")
        active = list(movable if active_joints is None else active_joints)
        for i, name in enumerate(active):
            if name not in movable:
                raise InvalidInputError(
                    f"active_joints[{i}] = {name!r} is not a movable joint on the chain from "
                    f"{self.base_link!r} to {end_link!r}; those are {movable}",
                    f"active_joints.{i}",
                )
        if len(set(active)) != len(active):
            raise InvalidInputError(f"active_joints repeats a joint: {active}", "active_joints")
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
        if (
            not isinstance(task, str)
            or not task
            or set(task) - set("xyz")
            or len(set(task)) < len(task)
        ):
            raise InvalidInputError(
                f"task must be 'xyz' or a subset of its letters such as 'xz', got {task!r}", "task"
            )  # fmt: skip
        self.task = task
        self.rows = np.array(["xyz".index(c) for c in task])
        self.joint_names = tuple(active)
        self.p, self.r = len(active), len(task)
        if self.p <= self.r:
            raise InvalidInputError(
                f"{self.p} active joints for a task of {self.r} coordinates: a redundant robot "
                "needs more joints than task coordinates",
                "active_joints",
            )
        self.variable_names = tuple(f"x{i + 1}" for i in range(self.p))
        self.chain = tuple(
            ChainJoint(
                j.name,
                {"fixed": "fixed", "prismatic": "prismatic"}.get(j.type, "revolute"),
                np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float),
                _unit(j.axis, j.name),
                active.index(j.name) if j.name in active else -1,
                float(locked.get(j.name, 0.0)),
            )
            for j in chain
        )  # fmt: skip
        self.limits = tuple(_limits(model.joint_map[name]) for name in active)
        self.locked = {j.name: j.value for j in self.chain if j.type != "fixed" and j.index < 0}
        self.urdf = urdf

    @property
    def parameters(self) -> dict[str, object]:
        return {"end_link": self.end_link, "active_joints": list(self.joint_names),
                "task": self.task, "locked": dict(self.locked)}  # fmt: skip

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

    def forward(self, x: FloatArray) -> FloatArray:
        """k(x): the end link's origin, the task's coordinates: (..., p) -> (..., r)."""
        return self.frames(x)[2][..., self.rows, 3]

    def jacobian(self, x: FloatArray) -> FloatArray:
        """J(x): (..., p) -> (..., r, p), analytic (see the class notes)."""
        x = np.asarray(x, dtype=float)
        o, z, T = self.frames(x)
        end = T[..., None, :3, 3]
        cols = np.zeros((*x.shape[:-1], 3, self.p))
        for k, j in enumerate(self.chain):
            if j.index < 0:
                continue
            if j.type == "revolute":
                cols[..., :, j.index] = np.cross(z[..., k, :], end[..., 0, :] - o[..., k, :])
            else:
                cols[..., :, j.index] = z[..., k, :]
        return cols[..., self.rows, :]


def _unit(axis, name: str) -> FloatArray:
    a = np.array([1.0, 0.0, 0.0]) if axis is None else np.asarray(axis, dtype=float)
    n = float(np.linalg.norm(a))
    if not n > 0 or not np.all(np.isfinite(a)):
        raise InvalidInputError(f"joint {name!r} has a zero or invalid axis", "urdf")
    return a / n


def _limits(joint) -> tuple[float, float]:
    """The joint's range [rad or m]: its URDF limits, or (-pi, pi) for a continuous joint."""
    lim = joint.limit
    if joint.type == "continuous" or lim is None or lim.lower is None or lim.upper is None:
        return (-math.pi, math.pi) if joint.type != "prismatic" else (-1.0, 1.0)
    lo, hi = float(lim.lower), float(lim.upper)
    return (lo, hi) if lo < hi else (-math.pi, math.pi)
