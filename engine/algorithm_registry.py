"""The catalogue of inverses J# for eq. (7) and :func:`make_inverse`, which builds one by name.

The REST API, the CLI and the dashboard list the algorithms and their parameters from
:data:`ALGORITHMS` (re-exported by :mod:`jik.engine.registry`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import practical_inverses as pinv
from .exceptions import InvalidInputError
from .inverses import ExtendedInverse, Inverse, Pseudoinverse
from .kinematics import Kinematics
from .limits import limited_box, robot_limits
from .parameters import Parameter, check_params
from .validation import as_vector

if TYPE_CHECKING:
    from .registry import RobotSpec


@dataclass(frozen=True)
class AlgorithmSpec:
    """An inverse J# for eq. (7): its equation, source and scalar parameters.

    ``vectors`` names its optional vector parameters (``rest``: p numbers; ``limits``: p pairs),
    whose length depends on the robot.
    """

    name: str
    equation: str
    source: str
    description: str
    parameters: tuple[Parameter, ...] = ()
    vectors: tuple[str, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        """Every parameter it takes: its scalars', then its vectors' names."""
        return (*(p.name for p in self.parameters), *self.vectors)

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "equation": self.equation,
            "source": self.source,
            "description": self.description,
            "parameters": [p.as_dict() for p in self.parameters],
            "vectors": list(self.vectors),
        }


ALGORITHMS: dict[str, AlgorithmSpec] = {
    a.name: a
    for a in (
        AlgorithmSpec(
            "pseudoinverse",
            "(8)",
            "the paper, eq. (8)",
            "Jacobian pseudoinverse J^T (J J^T)^-1: drifts on closed paths",
        ),
        AlgorithmSpec(
            "extended",
            "(11)",
            "the paper, eqs. (9)-(12)",
            "extended Jacobian inverse with an augmenting map h: repeatable",
        ),
        AlgorithmSpec(
            "damped",
            "J^T (J J^T + lambda^2 I)^-1",
            "Wampler (1986); adaptive damping: Nakamura and Hanafusa (1986)",
            "damped least squares: bounded joint speed through singularities, at a task error",
            (
                Parameter(
                    "damping",
                    pinv.DAMPING,
                    0.0,
                    pinv.MAX_DAMPING,
                    "damping lambda (0: the pseudoinverse)",
                ),
                Parameter(
                    "damping_threshold",
                    0.0,
                    0.0,
                    pinv.MAX_DAMPING,
                    "damp only where the smallest singular value of J is below this "
                    "(0: constant damping)",
                ),
            ),
        ),
        AlgorithmSpec(
            "weighted",
            "W^-1 J^T (J W^-1 J^T)^-1",
            "Chan and Dubey (1995)",
            "weighted least-norm inverse: joints slow down near their limits",
            vectors=("limits",),
        ),
        AlgorithmSpec(
            "posture",
            "J^# dy + (I - J^# J) k (x_rest - x) |dy|",
            "Liegeois (1977)",
            "pseudoinverse with a null-space pull toward a rest posture",
            (
                Parameter(
                    "gain",
                    pinv.GAIN,
                    0.0,
                    pinv.MAX_GAIN,
                    "null-space gain k per unit of path length (0: the pseudoinverse)",
                ),
            ),
            vectors=("rest",),
        ),
    )
}


def _robot_limits(kinematics: Kinematics, spec: RobotSpec | None, robot: str | None):
    """The weighted inverse's default limits: the robot's configuration box (a URDF arm's
    joint ranges, else the catalogue's ``x_range``) narrowed to its declared joint limits
    (:func:`~jik.engine.limits.robot_limits`, a planar chain's or formula robot's ``limits``) by
    :func:`~jik.engine.limits.limited_box`; limits finite on every side without a box. Finite
    but for a URDF arm's continuous joints, which have no limits (weight 1)."""
    from .registry import ROBOTS  # the robots' catalogue imports this module

    declared = robot_limits(kinematics)
    box = getattr(kinematics, "limits", None)
    if box is not None and declared is not None:  # (a URDF arm: a continuous joint is free)
        free = np.all(np.isinf(declared), axis=1)
        return np.where(free[:, None], declared, limited_box(box, declared))
    if box is None:
        spec = spec or ROBOTS.get(robot or kinematics.name)
        box = getattr(spec, "x_range", None) or None
    if box is not None:
        return limited_box(box, declared)
    if declared is not None and np.isfinite(declared).all():
        return declared
    raise InvalidInputError(
        f"{kinematics.name} has no joint limits: give the weighted inverse its limits, "
        "algorithm_parameters={'limits': [[lo, hi], ...]} (or WeightedInverse(robot, limits))",
        "limits",
    )


def default_rest(
    kinematics: Kinematics,
    x0=None,
    spec: RobotSpec | None = None,
    robot: str | None = None,
) -> tuple[list[float], str]:
    """The posture inverse's rest x_rest when none is given, and what it is ("home" or "x0"):
    the robot's home configuration, else the run's start ``x0``, else (no start given) the
    robot's default start in ``spec`` (or the catalogue's spec of ``robot``). The one rule of
    single runs, for the REST API and the dashboard alike; an atlas without rest pulls each run
    toward its own start instead (:mod:`jik.engine.posture_at_start`)."""
    from .registry import ROBOTS

    home = getattr(kinematics, "home", None)
    if home is not None:
        return [float(v) for v in home], "home"
    if x0 is None:
        spec = spec or ROBOTS.get(robot or kinematics.name)
        x0 = getattr(spec, "default_x0", None) or None
    if x0 is None:
        raise InvalidInputError(
            f"{kinematics.name} has no home posture: give the run's start x0=[...] or the rest, "
            "algorithm_parameters={'rest': [...]} (or PostureInverse(robot, rest))",
            "rest",
        )
    return [float(v) for v in as_vector(x0, kinematics.p, "x0")], "x0"


def make_inverse(
    kinematics: Kinematics,
    algorithm: str,
    augmentation: str | None = None,
    augmentation_parameters: Mapping[str, object] | None = None,
    robot: str | None = None,
    *,
    spec: RobotSpec | None = None,
    algorithm_parameters: Mapping[str, object] | None = None,
    x0=None,
) -> Inverse:
    """The inverse named ``algorithm`` (:data:`ALGORITHMS`) with its parameters.

    The extended inverse's map is looked up in ``spec`` (a robot defined by data,
    :mod:`jik.engine.robot_spec`), else in the spec of ``robot`` (default: the kinematics'
    name) in :data:`ROBOTS`. ``algorithm_parameters`` holds the algorithm's scalars
    (defaults from :data:`ALGORITHMS`) and vectors: ``limits`` of the weighted inverse (default:
    the robot's configuration box, a URDF arm's joint ranges else its catalogue box
    ``x_range``, narrowed to its declared joint limits, :func:`_robot_limits`) and ``rest`` of
    the posture inverse (given: within the robot's joint limits if it has some,
    :func:`~jik.engine.practical_inverses.check_rest`; default :func:`default_rest`, the
    robot's home, else the run's start ``x0``, else its default start, not checked against
    the limits; in an atlas each run's own start, :mod:`jik.engine.posture_at_start`). An
    ``augmentation`` (or its parameters) is the extended inverse's: another algorithm refuses it.
    """
    if algorithm not in ALGORITHMS:
        raise InvalidInputError(
            f"algorithm must be one of {list(ALGORITHMS)}, got {algorithm!r}", "algorithm"
        )
    if algorithm != "extended" and (augmentation is not None or augmentation_parameters):
        given_map = (
            augmentation if augmentation is not None else dict(augmentation_parameters or {})
        )
        raise InvalidInputError(
            f"augmentation: the {algorithm} inverse takes no augmenting map (the extended "
            f"inverse does), got {given_map!r}",
            "augmentation",
        )
    aspec_ = ALGORITHMS[algorithm]
    given = dict(algorithm_parameters or {})
    vectors = {k: given.pop(k) for k in aspec_.vectors if given.get(k) is not None}
    given = {k: v for k, v in given.items() if k not in aspec_.vectors}
    values = check_params(aspec_.parameters, given, f"algorithm {algorithm!r}", aspec_.vectors)
    if algorithm == "pseudoinverse":
        return Pseudoinverse(kinematics)
    if algorithm == "damped":
        return pinv.DampedInverse(kinematics, values["damping"], values["damping_threshold"])
    if algorithm == "weighted":
        if vectors.get("limits") is not None:  # (the default only without them: it may not exist)
            return pinv.WeightedInverse(kinematics, vectors["limits"])
        limits, declared = _robot_limits(kinematics, spec, robot), robot_limits(kinematics)
        # (the box, where no limit is declared: a URDF arm of continuous joints has none)
        box = (declared is None or not np.isfinite(declared).any()) and np.isfinite(limits).any()
        return pinv.WeightedInverse(kinematics, limits, bool(box))
    if algorithm == "posture":
        if "rest" in vectors:
            return pinv.PostureInverse(kinematics, vectors["rest"], values["gain"])
        rest, _ = default_rest(kinematics, x0, spec, robot)
        return pinv.PostureInverse(kinematics, rest, values["gain"], rest_given=False)
    from .registry import robot_spec

    aspec = (spec or robot_spec(robot or kinematics.name)).augmentation(augmentation)
    return ExtendedInverse(kinematics, aspec.build(kinematics, **(augmentation_parameters or {})))
