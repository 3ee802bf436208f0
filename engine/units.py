"""The units of a robot's coordinates: each joint variable's and each task coordinate's.

One description for every client (the dashboard's axes and exports, the REST API's catalogue
and responses, a notebook): :func:`robot_units` reads it from the kinematics.

- A revolute joint, an angle and a rotation coordinate are in rad; a prismatic joint and a
  position in m; ``"1"`` is dimensionless (Manipulator 1's x3, whose normal form (30) multiplies
  it with the length x1).
- A URDF arm is in SI units, as URDF files are: its positions x y z in m, its rotation vector
  rx ry rz in rad (:mod:`jik.engine.pose_task`).
- The paper states no units. Its manipulators' lengths (Manipulator 2's x1, x2, y and its arm
  length l, eq. (37)) share one length unit, here m; the unicycle's controls (41) are
  velocities over a horizon T in s, its pose q (40) in m and rad.
- A planar chain's lengths are in the unit of its link lengths, here m; its angles in rad.
- A formula robot's units are what its formulas mean: ``""``, not stated.

:attr:`RobotUnits.lengths` says, for each robot, what its length unit m stands for.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .exceptions import InvalidInputError
from .exports import coordinate_names
from .inverses import require_kinematics
from .limits import robot_limits
from .planar_chain import PlanarChain
from .urdf import UrdfChain
from .validation import of_type

#: The unit of each task coordinate of a pose task (:mod:`jik.engine.pose_task`) and of a
#: planar chain's (x, y, the end's angle phi).
TASK_UNITS = {"x": "m", "y": "m", "z": "m", "rx": "rad", "ry": "rad", "rz": "rad", "phi": "rad"}

#: The paper's robots, by kinematics name: the units of x, of y, and what the lengths are in.
PAPER_UNITS: dict[str, tuple[tuple[str, ...], tuple[str, ...], str]] = {
    "manipulator1": (
        ("m", "m", "1"),
        ("m", "m"),
        "the paper states no unit; its normal form's lengths x1, x2, y are read as m",
    ),
    "manipulator2": (
        ("m", "m", "rad"),
        ("m", "m"),
        "the unit of the arm length l, which the paper does not state; read as m",
    ),
    "unicycle": (
        ("m/s", "m/s", "rad/s", "rad/s"),
        ("m", "m", "rad"),
        "the paper states no unit; positions read as m, the horizon T as s",
    ),
}
#: What a planar chain's, a URDF arm's and a formula robot's lengths are in.
CHAIN_LENGTHS = "the unit of the link lengths, which a definition does not state; read as m"
URDF_LENGTHS = "m: SI units, as in a URDF"
NOT_STATED = "not stated: a formula robot's units are what its formulas mean"


@dataclass(frozen=True)
class Coordinate:
    """A joint variable or a task coordinate.

    Attributes
    ----------
    name : str
        Its name (``x1``, ``rz``).
    unit : str
        ``"rad"``, ``"m"``, ``"1"`` (dimensionless), ``"m/s"``, ``"rad/s"``, or ``""`` (not
        stated).
    joint : str or None
        A URDF arm's joint of this variable (``panda_joint1``).
    limits : (float or None, float or None) or None
        The joint's [lower, upper] limits (None: no bound on that side); None without limits.
    home : float or None
        Its value at the arm's home configuration.
    """

    name: str
    unit: str
    joint: str | None = None
    limits: tuple[float | None, float | None] | None = None
    home: float | None = None

    def as_dict(self) -> dict:
        """JSON-friendly, the fields a coordinate has (``name`` and ``unit`` always)."""
        out: dict = {"name": self.name, "unit": self.unit}
        for key in ("joint", "limits", "home"):
            value = getattr(self, key)
            if value is not None:
                out[key] = list(value) if key == "limits" else value
        return out


@dataclass(frozen=True)
class RobotUnits:
    """A robot's joint variables and task coordinates with their units.

    Attributes
    ----------
    variables : tuple of Coordinate, shape (p,)
        In x's order, with a URDF arm's joint names, the joint limits and the home.
    task : tuple of Coordinate, shape (r,)
        In k(x)'s order.
    lengths : str
        What the robot's length unit m stands for (the paper states none).
    """

    variables: tuple[Coordinate, ...]
    task: tuple[Coordinate, ...]
    lengths: str

    def __repr__(self) -> str:
        """One line: each coordinate with its unit (where stated) and a variable's joint, and
        whether any variable has limits and a home."""

        def words(coordinates: tuple[Coordinate, ...]) -> str:
            said = ((c.name, f"[{c.unit}]" if c.unit else "", c.joint or "") for c in coordinates)
            return "(" + ", ".join(" ".join(filter(None, each)) for each in said) + ")"

        has = {
            k: any(getattr(c, k) is not None for c in self.variables) for k in ("limits", "home")
        }
        return (
            f"RobotUnits(x={words(self.variables)}, y={words(self.task)}, "
            f"limits={has['limits']}, home={has['home']})"
        )

    @property
    def x(self) -> tuple[str, ...]:
        """The unit of each joint variable, (p,)."""
        return tuple(c.unit for c in self.variables)

    @property
    def y(self) -> tuple[str, ...]:
        """The unit of each task coordinate, (r,)."""
        return tuple(c.unit for c in self.task)

    def columns(self) -> dict[str, Coordinate]:
        """The coordinates under the names of their columns in the engine's tables
        (:func:`jik.engine.exports.coordinate_names`): ``x_1``..``x_p`` the joint variables,
        then ``y_1``..``y_r`` the task coordinates."""
        return {
            **dict(zip(coordinate_names("x", len(self.variables)), self.variables, strict=True)),
            **dict(zip(coordinate_names("y", len(self.task)), self.task, strict=True)),
        }

    def trajectory_units(self, mode: str) -> dict[str, str]:
        """The unit of each column of a run's table
        (:meth:`jik.engine.results.Trajectory.columns`), spelled out: ``theta`` (iterations in
        ``mode`` "discrete", else dimensionless), ``x_k`` and ``y_k`` (:meth:`columns`), the
        task ``error`` (a norm of y, :func:`norm_unit`) and ``h``."""
        spelled = {"": "as the definition's formulas", "1": "dimensionless"}
        return {
            "theta": "iterations" if mode == "discrete" else "dimensionless",
            **{k: spelled.get(c.unit, c.unit) for k, c in self.columns().items()},
            "error": norm_unit(self.y).strip("[]") or "as y",
            "h": "the unit of the map's formula",
        }

    def summary(self) -> dict:
        """``{"x": units of x, "y": units of y, "lengths": ...}``, JSON-friendly: what a run's
        document says of its configurations x and task points y."""
        return {"x": list(self.x), "y": list(self.y), "lengths": self.lengths}

    def as_dict(self) -> dict:
        """``{"variables": [...], "task": [...], "lengths": ...}``, JSON-friendly."""
        return {
            "variables": [c.as_dict() for c in self.variables],
            "task": [c.as_dict() for c in self.task],
            "lengths": self.lengths,
        }


def norm_unit(unit_names: Sequence[str]) -> str:
    """The unit of a Euclidean norm of coordinates in ``unit_names`` (a drift ||x - x0||, a
    task error): one unit, or the units it mixes said so ("1": dimensionless); "" when none is
    stated."""
    names = [("dimensionless" if u == "1" else u) for u in dict.fromkeys(unit_names) if u]
    if len(names) <= 1:
        return f"[{names[0]}]" if names else ""
    return f"[{' and '.join(names)} mixed]"


def _units(kinematics, task_names: Sequence[str]) -> tuple[tuple[str, ...], tuple[str, ...], str]:
    """(units of x, units of y, what the lengths are in) of ``kinematics``."""
    p, r = kinematics.p, len(task_names)
    if isinstance(kinematics, PlanarChain):
        joints = tuple("rad" if revolute else "m" for revolute in kinematics.revolute)
        return joints, tuple(TASK_UNITS[n] for n in ("x", "y", "phi")[:r]), CHAIN_LENGTHS
    if isinstance(kinematics, UrdfChain):
        kinds = {j.index: j.type for j in kinematics.chain if j.index >= 0}
        joints = tuple("m" if kinds[i] == "prismatic" else "rad" for i in range(p))
        return joints, tuple(TASK_UNITS[n] for n in task_names), URDF_LENGTHS
    paper = PAPER_UNITS.get(getattr(kinematics, "name", ""))
    if paper is not None and len(paper[0]) == p and len(paper[1]) == r:
        return paper
    return ("",) * p, ("",) * r, NOT_STATED


def robot_units(kinematics, task_names: Sequence[str] | None = None) -> RobotUnits:
    """The units of a robot's joint variables and task coordinates (see the module docstring),
    with a URDF arm's joint names and home, and the joint limits where the robot has them.

    Parameters
    ----------
    kinematics : Kinematics
    task_names : sequence of str, shape (r,), optional
        The task coordinates' names (a spec's ``task_names``); default: the kinematics' own
        (a URDF arm's), else ``y1 .. yr``.

    Raises
    ------
    InvalidInputError
        ``kinematics`` not a Kinematics; ``task_names`` not r strings.
    """
    kinematics = require_kinematics(kinematics)
    if task_names is None:
        default = tuple(f"y{i + 1}" for i in range(kinematics.r))
        task_names = getattr(kinematics, "task_names", None) or default
    names = _task_names(task_names, kinematics.r)
    x, y, lengths = _units(kinematics, names)
    limits = robot_limits(kinematics)
    bounds = [None] * kinematics.p if limits is None else [_bounds(b) for b in limits]
    joints = getattr(kinematics, "joint_names", None) or (None,) * kinematics.p
    home = getattr(kinematics, "home", None)
    homes = (None,) * kinematics.p if home is None else tuple(float(v) for v in home)
    variables = tuple(
        Coordinate(*fields)
        for fields in zip(kinematics.variable_names, x, joints, bounds, homes, strict=True)
    )
    task = tuple(Coordinate(n, u) for n, u in zip(names, y, strict=True))
    return RobotUnits(variables, task, lengths)


def _task_names(task_names, r: int) -> tuple[str, ...]:
    """``task_names`` as a tuple of r strings, else an InvalidInputError naming it."""
    names = of_type(task_names, Sequence, "task_names", f"a list of {r} names")
    if isinstance(names, str) or len(names) != r or not all(isinstance(n, str) for n in names):
        raise InvalidInputError(
            f"task_names must be {r} strings, one per task coordinate (r = {r}), got "
            f"{task_names!r:.80}",
            "task_names",
        )
    return tuple(names)


def _bounds(pair) -> tuple[float | None, float | None]:
    """A joint's [lower, upper] with None for an infinite side (JSON has no infinity)."""
    lo, hi = (float(v) for v in pair)
    return (lo if np.isfinite(lo) else None, hi if np.isfinite(hi) else None)
