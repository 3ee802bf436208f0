"""Catalogue of robots and augmenting maps with their parameters, ranges and defaults.

The REST API, the CLI and the dashboard build everything from here, so no client hard-codes a
range. Each robot lists its augmentations; each parameter its default and range.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

from . import augmentations as aug
from .algorithm_registry import ALGORITHMS as ALGORITHMS
from .algorithm_registry import AlgorithmSpec as AlgorithmSpec
from .algorithm_registry import make_inverse as make_inverse
from .augmentations import AugmentingMap
from .characteristics import UnicycleCharacteristics
from .exceptions import InvalidInputError
from .kinematics import Kinematics, Manipulator1, Manipulator2
from .parameters import Parameter as Parameter
from .parameters import check_params as _check_params
from .solve_rules import Mode
from .unicycle import Unicycle
from .validation import finite
from .variational import MANIPULATOR2_REGION, default_manipulator2_synthesis


@dataclass(frozen=True)
class AugmentationSpec:
    """An augmenting map h of the paper, eq. (9), and how to build it."""

    name: str
    equation: str
    description: str
    parameters: tuple[Parameter, ...]
    factory: Callable[..., AugmentingMap] = field(repr=False)

    def build(self, kinematics: Kinematics, **values) -> AugmentingMap:
        return self.factory(kinematics, **_check_params(self.parameters, values, self.name))

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "equation": self.equation,
            "description": self.description,
            "parameters": [p.as_dict() for p in self.parameters],
        }


@dataclass(frozen=True)
class VectorSpec:
    """A vector-valued robot parameter (the unicycle's initial pose q0)."""

    name: str
    default: tuple[float, ...]
    minimum: tuple[float, ...]
    maximum: tuple[float, ...]
    description: str
    presets: Mapping[str, tuple[float, ...]] = field(default_factory=dict)

    def check(self, value) -> tuple[float, ...]:
        try:
            v = tuple(finite(t, self.name) for t in value)
        except TypeError as exc:
            raise InvalidInputError(
                f"{self.name} must be a list of {len(self.default)} numbers", self.name
            ) from exc
        if len(v) != len(self.default):
            raise InvalidInputError(
                f"{self.name} must have {len(self.default)} components, got {len(v)}", self.name
            )
        for i, (t, lo, hi) in enumerate(zip(v, self.minimum, self.maximum, strict=True)):
            if not lo <= t <= hi:
                raise InvalidInputError(
                    f"{self.name}[{i}] must be in [{lo:g}, {hi:g}], got {t:g}", f"{self.name}.{i}"
                )
        return v

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "default": list(self.default),
            "minimum": list(self.minimum),
            "maximum": list(self.maximum),
            "description": self.description,
            "presets": {k: list(v) for k, v in self.presets.items()},
        }


@dataclass(frozen=True)
class RobotSpec:
    """A robot of the paper: its kinematics, defaults and augmentations."""

    name: str
    title: str
    description: str
    equation: str
    p: int
    r: int
    variable_names: tuple[str, ...]
    task_names: tuple[str, ...]
    parameters: tuple[Parameter, ...]
    vector_parameters: tuple[VectorSpec, ...]
    factory: Callable[..., Kinematics] = field(repr=False)
    default_x0: tuple[float, ...] = ()
    default_target: tuple[float, ...] = ()
    default_path: tuple[tuple[float, ...], ...] = ()
    #: Whether ``default_path`` is a closed task path to drive cycle after cycle (False: the
    #: targets of an experiment, the unicycle's of sec. 6.2, which a platform reaches once).
    default_path_loops: bool = True
    default_mode: Mode = "continuous"
    default_gamma: float = 1.0
    x_range: tuple[tuple[float, float], ...] = ()
    augmentations: tuple[AugmentationSpec, ...] = ()
    default_augmentation: str = ""
    #: The box on which the paper evaluates E1, E2 (sec. 5); empty where it gives none.
    functional_region: Mapping[str, tuple[float, float]] = field(default_factory=dict)

    def build(self, **values) -> Kinematics:
        scalars = {
            k: v for k, v in values.items() if k not in {p.name for p in self.vector_parameters}
        }
        args = _check_params(self.parameters, scalars, self.name)
        for vp in self.vector_parameters:
            args[vp.name] = vp.check(values.get(vp.name, vp.default))
        return self.factory(**args)

    def default_loop(self, field: str = "path") -> list[list[float]]:
        """The default closed path of a repeatability run or an atlas, as lists.

        Raises
        ------
        InvalidInputError
            Naming ``field`` when the robot has none (its default path, if any, is an
            experiment's targets: :attr:`default_path_loops`).
        """
        if self.default_path and self.default_path_loops:
            return [list(t) for t in self.default_path]
        why = (
            f": its default path {[list(t) for t in self.default_path]} is the targets of the "
            "paper's experiment, reached once, not a loop"
            if self.default_path
            else ""
        )
        raise InvalidInputError(f"{self.name} has no default closed path{why}: give {field}", field)

    def augmentation(self, name: str | None) -> AugmentationSpec:
        name = name or self.default_augmentation
        for a in self.augmentations:
            if a.name == name:
                return a
        raise InvalidInputError(
            f"unknown augmentation {name!r} for {self.name}; "
            f"choose one of {[a.name for a in self.augmentations]}",
            "augmentation",
        )

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "title": self.title,
            "description": self.description,
            "equation": self.equation,
            "p": self.p,
            "r": self.r,
            "variable_names": list(self.variable_names),
            "task_names": list(self.task_names),
            "parameters": [p.as_dict() for p in self.parameters]
            + [v.as_dict() for v in self.vector_parameters],
            "default_x0": list(self.default_x0),
            "default_target": list(self.default_target),
            "default_path": [list(t) for t in self.default_path],
            "default_path_loops": self.default_path_loops,
            "default_mode": self.default_mode,
            "default_gamma": self.default_gamma,
            "x_range": [list(t) for t in self.x_range],
            "augmentations": [a.as_dict() for a in self.augmentations],
            "default_augmentation": self.default_augmentation,
            "functional_region": {k: list(v) for k, v in self.functional_region.items()},
        }


_AB = 5.0
#: The box of sec. 5.1 on which E1, E2 of Manipulator 1's maps are compared.
MANIPULATOR1_REGION = {"x1": (0.0, 1.0), "x2": (0.0, 1.0), "x3": (0.5, 1.5)}

MANIPULATOR1 = RobotSpec(
    name="manipulator1",
    title="Manipulator 1",
    description="3DOF manipulator in the normal form k(x) = (x1, x2 + x1 x3)",
    equation="(30)",
    p=3,
    r=2,
    variable_names=("x1", "x2", "x3"),
    task_names=("y1", "y2"),
    parameters=(),
    vector_parameters=(),
    factory=Manipulator1,
    default_x0=Manipulator1.start,
    default_target=(0.8, 1.5),
    default_path=((0.8, 1.0), (0.8, 1.6), (0.3, 1.6), (0.5, 1.0)),
    x_range=((-2.0, 2.0), (-2.0, 2.0), (-2.0, 2.0)),
    augmentations=(
        AugmentationSpec(
            "e2_optimal",
            "(36)",
            "E2-optimal h = x3 (a x1 + b) sqrt(1 + x1^2)",
            (
                Parameter("a", 0.0, -_AB, _AB, "integration constant a of (36)"),
                Parameter("b", 1.0, -_AB, _AB, "integration constant b of (36)"),
            ),
            lambda kin, a, b: aug.E2Optimal(a, b),
        ),
        AugmentationSpec(
            "e1_optimal",
            "(32)",
            "E1 map h = x3 C1 sqrt(1 + x1^2) / (x1 sqrt(1 + x1^2) + asinh x1 + C2)^(1/3)",
            (
                Parameter("C1", 1.0, -_AB, _AB, "integration constant C1 of (32)", nonzero=True),
                Parameter("C2", 1.0, -_AB, _AB, "integration constant C2 of (32)"),
            ),
            lambda kin, C1, C2: aug.E1Optimal(C1, C2),
        ),
        AugmentationSpec(
            "e1_taylor",
            "(33)",
            "Taylor approximation h = x3 (1 - 2 x1 / 3) sqrt(1 + x1^2)",
            (),
            lambda kin: aug.E1Taylor(),
        ),
    ),
    default_augmentation="e2_optimal",
    functional_region=MANIPULATOR1_REGION,
)

MANIPULATOR2 = RobotSpec(
    name="manipulator2",
    title="Manipulator 2",
    description="XY gantry with a revolute arm: k(x) = (x2 + l cos x3, x1 + l sin x3)",
    equation="(37)",
    p=3,
    r=2,
    variable_names=("x1", "x2", "x3"),
    task_names=("y1", "y2"),
    parameters=(Parameter("l", 1.0, 0.1, 5.0, "arm length"),),
    vector_parameters=(),
    factory=Manipulator2,
    default_x0=Manipulator2.start,
    default_target=(0.0, 2.0),
    default_path=((1.0, 1.0), (1.0, 2.0), (0.0, 2.0), (0.0, 1.0)),
    x_range=((-3.0, 3.0), (-3.0, 3.0), (-math.pi, 2 * math.pi)),
    augmentations=(
        AugmentationSpec(
            "paper_cubic",
            "(38)",
            "the paper's cubic fit h(x2, x3), exactly as printed, with its exact gradient",
            (),
            lambda kin: aug.PaperCubic(),
        ),
    ),
    default_augmentation="paper_cubic",
    functional_region=MANIPULATOR2_REGION,
)


def _e2_synthesized(kin: Manipulator2) -> AugmentingMap:
    return default_manipulator2_synthesis(kin.l).augmenting_map


MANIPULATOR2 = replace(
    MANIPULATOR2,
    augmentations=(
        *MANIPULATOR2.augmentations,
        AugmentationSpec(
            "e2_synthesized",
            "(20)",
            "E2-optimal h(x2, x3) on x2 in [-1, 1], x3 in [0, pi], synthesized by a spectral Ritz "
            "solve of the Euler equation (20) (computed once per arm length, about a second)",
            (),
            _e2_synthesized,
        ),
    ),
)

#: Section 6.2's start poses of the platform.
POSE_A = (5.0, 0.0, math.pi / 2)
POSE_B = (-5.0, 5.0, math.pi / 2)

UNICYCLE = RobotSpec(
    name="unicycle",
    title="Unicycle",
    description="unicycle (40) driven by Fourier controls (41): k(lambda) = q(T), eq. (42)",
    equation="(40)-(42)",
    p=4,
    r=3,
    variable_names=("lambda10", "lambda11", "lambda20", "lambda21"),
    task_names=("q1", "q2", "q3"),
    parameters=(Parameter("T", 2 * math.pi, 0.5, 20.0, "control horizon T [s]"),),
    vector_parameters=(
        VectorSpec(
            "q0",
            POSE_A,
            (-20.0, -20.0, -2 * math.pi),
            (20.0, 20.0, 2 * math.pi),
            "initial pose (q1 [m], q2 [m], q3 [rad])",
            presets={"A": POSE_A, "B": POSE_B},
        ),
    ),
    factory=lambda T, q0: Unicycle(q0=q0, T=T),
    default_x0=Unicycle.start,
    default_target=(1.0, 0.0, -math.pi / 2),
    default_path=((1.0, 0.0, -math.pi / 2), (3.0, 2.0, 0.0)),
    default_path_loops=False,
    default_mode="discrete",
    default_gamma=0.1,
    x_range=((-3.0, 3.0), (-3.0, 3.0), (-3.0, 3.0), (-3.0, 3.0)),
    augmentations=(
        AugmentationSpec(
            "characteristics",
            "(28), (29), (45)",
            "h by the method of characteristics toward the reference leaf E_{a,0} = a e1 + R e2",
            (
                Parameter(
                    "a",
                    1.0,
                    -5.0,
                    5.0,
                    "reference leaf lambda10 = a (omega undefined at 0)",
                    nonzero=True,
                ),
            ),
            lambda kin, a: UnicycleCharacteristics(kin, a),
        ),
    ),
    default_augmentation="characteristics",
)

ROBOTS: dict[str, RobotSpec] = {s.name: s for s in (MANIPULATOR1, MANIPULATOR2, UNICYCLE)}


def robot_spec(name: str) -> RobotSpec:
    """The spec of robot ``name``; a clear error listing the known ones otherwise."""
    try:
        return ROBOTS[name]
    except KeyError:
        raise InvalidInputError(
            f"unknown robot {name!r}; choose one of {sorted(ROBOTS)}", "robot"
        ) from None
