"""Which inverses J# the dashboard runs: the chosen algorithms of the engine's catalogue
(:data:`jik.engine.registry.ALGORITHMS`), their parameters, and how each is drawn everywhere.

A state chooses one to five algorithms (``algorithms``, default the paper's two, eqs. (8) and
(11)) and holds the scalar parameters of the chosen ones (``algorithm_parameters``: ``damping``
and ``damping_threshold`` of damped least squares, ``gain`` of the posture inverse), with their
ranges from the engine's :class:`~jik.engine.parameters.Parameter`. The posture inverse's rest
is the robot's home, else the state's start x0; the weighted inverse takes the robot's joint
limits (else its configuration box), and is refused naming ``algorithms`` for a robot with
neither. :data:`STYLES` gives each algorithm one colour, line style, marker, label and 3D copy,
used by the scene, every plot, the drift panel and the atlas. :func:`cache_key` says what one
algorithm's run depends on (its own parameters included).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from ...engine.exceptions import InvalidInputError
from ...engine.registry import ALGORITHMS as REGISTRY
from ..compute.schemas.algorithms import Algorithm


class ChosenState(Protocol):
    """What these functions read of a :class:`jik.app.dashboard.model.DashboardState` (which
    imports this module)."""

    @property
    def algorithms(self) -> Sequence[str]: ...
    @property
    def algorithm_parameters(self) -> Mapping[str, float]: ...
    @property
    def x0(self) -> Sequence[float]: ...
    @property
    def mode(self) -> str: ...

    def as_dict(self) -> dict: ...


#: Every algorithm a state may choose, in the catalogue's order (the order they are drawn in).
CHOICES = tuple(REGISTRY)
#: The algorithms of a new state: the paper's pseudoinverse (8) and extended Jacobian (11).
DEFAULT_ALGORITHMS: tuple[Algorithm, ...] = ("pseudoinverse", "extended")


@dataclass(frozen=True)
class Style:
    """How one algorithm is drawn: ``color`` everywhere, ``dash`` (plotly's) and ``symbol``
    (a marker) in the plots, ``label``/``short`` its names, ``line``/``robot`` the key's words,
    and its copy in the 3D scene: ``opacity`` (None: solid) at height ``z``."""

    color: str
    dash: str
    symbol: str
    label: str
    short: str
    line: str
    robot: str
    opacity: float | None
    z: float
    width: float = 1.8


STYLES: dict[str, Style] = {
    "pseudoinverse": Style(
        "#d62728",
        "solid",
        "circle",
        "pseudoinverse J^P# (8)",
        "J^P# (8)",
        "solid line",
        "translucent robot",
        0.55,
        0.10,
        4.0,
    ),
    "extended": Style(
        "#1f77b4",
        "dash",
        "diamond",
        "extended Jacobian J^E# (11)",
        "J^E# (11)",
        "dashed line",
        "opaque robot",
        None,
        0.0,
    ),
    "damped": Style(
        "#ff7f0e",
        "dot",
        "square",
        "damped least squares J^DLS",
        "DLS",
        "dotted line",
        "translucent orange robot",
        0.6,
        0.05,
        2.5,
    ),
    "weighted": Style(
        "#8c564b",
        "dashdot",
        "triangle-up",
        "weighted least-norm J^W#",
        "J^W#",
        "dash-dotted line",
        "translucent brown robot",
        0.6,
        0.15,
        2.5,
    ),
    "posture": Style(
        "#17becf",
        "longdash",
        "star",
        "posture J^P# + null space k(x_rest - x)",
        "posture",
        "long-dashed line",
        "translucent teal robot",
        0.6,
        0.20,
        2.5,
    ),
}
assert set(STYLES) == set(CHOICES)
COLORS = {a: s.color for a, s in STYLES.items()}
DASH = {a: s.dash for a, s in STYLES.items()}
LABELS = {a: s.label for a, s in STYLES.items()}


def scalar_parameters(algorithms) -> tuple:
    """The engine's :class:`~jik.engine.parameters.Parameter` of each chosen algorithm."""
    return tuple(p for a in algorithms for p in REGISTRY[a].parameters)


def checked(algorithms: tuple[str, ...], given: Mapping[str, Any]) -> dict[str, Any]:
    """The chosen algorithms in the catalogue's order and their scalar parameters (the given
    ones checked against the engine's ranges, the others at their defaults; parameters of
    algorithms not chosen are dropped).

    Raises
    ------
    InvalidInputError
        ``algorithms`` when one is chosen twice; ``algorithm_parameters.<name>`` for a value out
        of its range or a name no algorithm has.
    """
    twice = sorted({a for a in algorithms if algorithms.count(a) > 1})
    if twice:
        raise InvalidInputError(f"algorithms: {twice} chosen twice; choose each once", "algorithms")
    known = {p.name for p in scalar_parameters(CHOICES)}
    for name in given:
        if name not in known:
            raise InvalidInputError(
                f"algorithm_parameters.{name}: no algorithm has this parameter; known: "
                f"{sorted(known)}",
                f"algorithm_parameters.{name}",
            )
    ordered = tuple(a for a in CHOICES if a in algorithms)
    values = {}
    for p in scalar_parameters(ordered):
        try:
            values[p.name] = p.check(given.get(p.name, p.default))
        except InvalidInputError as exc:
            field = f"algorithm_parameters.{p.name}"
            raise InvalidInputError(f"{field}: {exc}", field) from None
    return {"algorithms": ordered, "algorithm_parameters": values}


def inverse_parameters(state: ChosenState, algorithm: str, kin) -> dict[str, Any]:
    """What the engine's ``make_inverse`` takes for ``algorithm``: its scalars, and the posture
    inverse's rest at the state's x0 when the robot has no home."""
    names = {p.name for p in REGISTRY[algorithm].parameters}
    out: dict[str, Any] = {k: v for k, v in state.algorithm_parameters.items() if k in names}
    if algorithm == "posture" and getattr(kin, "home", None) is None:
        out["rest"] = list(state.x0)
    return out


def check_inverses(state: ChosenState, build) -> None:
    """Build the chosen algorithms other than the paper's two (``build(algorithm)``, cheap),
    so that a robot without joint limits refuses the weighted inverse here, naming
    ``algorithms``."""
    for a in state.algorithms:
        if a in DEFAULT_ALGORITHMS:
            continue
        try:
            build(a)
        except InvalidInputError as exc:
            raise InvalidInputError(
                f"algorithms: {a} cannot run on this robot: {exc}", "algorithms"
            ) from None


def cache_key(state: ChosenState, algorithm: str) -> str:
    """Everything one algorithm's run depends on: the state without what only a panel shows,
    the other algorithms' parameters, the map (but for the extended inverse) and gamma in
    continuous mode (see :mod:`jik.app.dashboard.results`)."""
    d = state.as_dict()
    d.pop("cspace_axes")  # (what a panel shows, not what is solved)
    d.pop("algorithms")
    names = {p.name for p in REGISTRY[algorithm].parameters}
    d["algorithm_parameters"] = {k: v for k, v in d["algorithm_parameters"].items() if k in names}
    d["algorithm"] = algorithm
    if algorithm != "extended":
        d.pop("augmentation"), d.pop("augmentation_parameters")
    if state.mode == "continuous":
        d.pop("gamma")
    return json.dumps(d, sort_keys=True)


def runs_key(state: ChosenState) -> tuple[str, ...]:
    """Everything the runs of the chosen algorithms depend on, up to the scale of theta.

    Two states with the same key have the same configurations along the same legs (in
    continuous mode gamma only divides theta).
    """
    return tuple(cache_key(state, a) for a in state.algorithms)
