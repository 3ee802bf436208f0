"""Which inverses J# the dashboard runs: the chosen algorithms of the engine's catalogue
(:data:`jik.engine.registry.ALGORITHMS`, default the paper's two, eqs. (8) and (11)), their
parameters (the scalars with the engine's ranges, :func:`checked`; the posture inverse's rest
x_rest, :func:`checked_rest`), how each is drawn everywhere (:data:`STYLES`), and what one
algorithm's run depends on (:func:`cache_key`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ...engine.algorithm_registry import default_rest
from ...engine.exceptions import InvalidInputError
from ...engine.limits import limited_box, robot_limits
from ...engine.practical_findings import rest_words as engine_rest_words
from ...engine.practical_inverses import check_rest
from ...engine.registry import ALGORITHMS as REGISTRY
from ...engine.validation import within
from ..compute.schemas.algorithms import Algorithm
from ..compute.schemas.wording import refused, without_field


class ChosenState(Protocol):
    """What these functions read of a :class:`jik.app.dashboard.model.DashboardState` (which
    imports this module: importing it here, even for the type checker, is a cycle)."""

    @property
    def algorithms(self) -> Sequence[str]: ...
    @property
    def algorithm_parameters(self) -> Mapping[str, Any]: ...
    @property
    def x0(self) -> Sequence[float]: ...
    @property
    def mode(self) -> str: ...

    def as_dict(self) -> dict: ...


#: Every algorithm a state may choose, in the catalogue's order (the order they are drawn in).
CHOICES = tuple(REGISTRY)
#: The algorithms of a new state: the paper's pseudoinverse (8) and extended Jacobian (11).
DEFAULT_ALGORITHMS: tuple[Algorithm, ...] = ("pseudoinverse", "extended")
#: The vector parameters a state sets, by the algorithm that takes them (the weighted inverse's
#: limits are the robot's).
VECTORS = {"rest": "posture"}
#: The range of each joint variable of a robot without a configuration box (x0's sliders).
DEFAULT_BOX = (-10.0, 10.0)


@dataclass(frozen=True)
class Style:
    """How one algorithm is drawn: ``color`` everywhere, ``dash`` (plotly's) and ``symbol``
    (a marker) in the plots, ``label``/``short`` its names (in the verdict's sentences:
    :data:`jik.engine.findings.NAMES`), ``line``/``robot`` the key's words, and its copy in the
    3D scene: ``opacity`` (None: solid) at height ``z``."""

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


def check_names(given: Mapping[str, Any]) -> None:
    """Refuse a name of ``algorithm_parameters`` no dashboard control sets: the weighted
    inverse's ``limits``, which the REST API takes, are the robot's here (its definition's
    ``limits``, a URDF's joints)."""
    known = {p.name for p in scalar_parameters(CHOICES)} | set(VECTORS)
    for name in given:
        if name == "limits":
            why = (
                "the dashboard's weighted inverse keeps to the robot's own joint limits; give "
                "them in the robot's definition (limits, or a URDF's joints)"
            )
        elif name not in known:
            why = f"no algorithm has this parameter; known: {sorted(known)}"
        else:
            continue
        raise refused(f"algorithm_parameters.{name}", why)


def checked(algorithms: tuple[str, ...], given: Mapping[str, Any]) -> dict[str, Any]:
    """The chosen algorithms in the catalogue's order and their scalar parameters (the given
    ones checked against the engine's ranges, the others at their defaults; parameters of
    algorithms not chosen are checked, then dropped). A vector parameter (:data:`VECTORS`) is
    kept as given when its algorithm is chosen: its check needs the robot (:func:`checked_rest`).

    Raises
    ------
    InvalidInputError
        ``algorithms`` when one is chosen twice; ``algorithm_parameters.<name>`` for a value out
        of its range or a name no algorithm has.
    """
    twice = sorted({a for a in algorithms if algorithms.count(a) > 1})
    if twice:
        raise InvalidInputError(f"algorithms: {twice} chosen twice; choose each once", "algorithms")
    check_names(given)
    ordered = tuple(a for a in CHOICES if a in algorithms)
    values = {}
    chosen = scalar_parameters(ordered)
    for p in scalar_parameters(CHOICES):
        if p in chosen or p.name in given:
            try:
                value = p.check(given.get(p.name, p.default))
            except InvalidInputError as exc:
                field = f"algorithm_parameters.{p.name}"
                raise refused(field, without_field(str(exc), exc.field)) from None
            if p in chosen:
                values[p.name] = value
    values.update({k: given[k] for k, a in VECTORS.items() if a in ordered and k in given})
    return {"algorithms": ordered, "algorithm_parameters": values}


def joint_box(spec, kin) -> tuple[tuple[float, float], ...]:
    """The range of each slider of a joint configuration, x0's and the posture rest's (what
    :func:`checked_rest` accepts): the robot's joint limits, its ``x_range`` else
    :data:`DEFAULT_BOX` on a side without a limit, or that range's width beyond a finite limit
    it lies on the other side of (:func:`~jik.engine.limits.limited_box`)."""
    x_range = spec.x_range or (DEFAULT_BOX,) * len(spec.variable_names)
    box = limited_box(x_range, robot_limits(kin))
    return tuple((float(a), float(b)) for a, b in box)


def checked_rest(value, spec, kin, x0) -> tuple[float, ...] | None:
    """The posture inverse's rest x_rest as set (``algorithm_parameters.rest``), checked: p
    finite numbers, within the robot's joint limits if it has some (the engine's
    :func:`~jik.engine.practical_inverses.check_rest`) and within the range of its sliders
    (:func:`joint_box`); None when it is the robot's home, the default in force. A rest equal
    to the start ``x0`` stays set: the default would follow the start as it moves.

    Raises
    ------
    InvalidInputError
        ``algorithm_parameters.rest`` for a wrong length, ``algorithm_parameters.rest.<i>``
        for a coordinate not finite, outside its joint's limits or outside its slider.
    """
    field, names = "algorithm_parameters.rest", spec.variable_names
    each = f"one per joint variable ({', '.join(names)})"
    if not isinstance(value, tuple | list):
        raise refused(field, f"give {len(names)} numbers, {each}")
    if len(value) != len(names):
        raise refused(field, f"give {len(names)} entries, {each}, got {len(value)}")
    for i, v in enumerate(value):
        if not math.isfinite(v):
            raise refused(f"{field}.{i}", "Input should be a finite number")
    rest = tuple(float(v) for v in value)
    if default_rest(kin, x0) == (list(rest), "home"):
        return None
    try:
        check_rest(kin, rest)
        within(rest, joint_box(spec, kin), "rest", names, "the range of the rest's sliders")
    except InvalidInputError as exc:
        where = f"algorithm_parameters.{exc.field}"
        raise refused(where, without_field(str(exc), exc.field)) from None
    return rest


def posture_rest(state: ChosenState, kin) -> tuple[list[float], str]:
    """The posture inverse's rest in force and what it is: "set" (the state's), else the
    default's "home" or "x0" (:func:`~jik.engine.algorithm_registry.default_rest`)."""
    given = state.algorithm_parameters.get("rest")
    if given is not None:
        return [float(v) for v in given], "set"
    return default_rest(kin, state.x0)


def editable_rest(state: ChosenState, spec, kin) -> list[float]:
    """The rest that one rest slider moved changes: the state's, else the default in force
    brought into the sliders' range (:func:`joint_box`), as the sliders show it (a rest set is
    checked: the coordinates the user did not touch take the nearest value accepted)."""
    rest, source = posture_rest(state, kin)
    if source == "set":
        return rest
    lo, hi = np.array(joint_box(spec, kin)).T
    return [float(v) for v in np.clip(rest, lo, hi)]


def rest_words(state: ChosenState, spec, inverse) -> str:
    """The rest in force in words, for the verdict (the engine's
    :func:`~jik.engine.practical_findings.rest_words` for the posture ``inverse``); a default
    outside the rest's sliders (:func:`joint_box`: the joint limits) says what moving one of
    them makes of it (:func:`editable_rest`)."""
    words = engine_rest_words(inverse, state.x0)
    kin = inverse.kinematics
    rest, source = posture_rest(state, kin)
    if source == "set":
        return words
    near = editable_rest(state, spec, kin)
    moved = [
        f"{n} = {b:.4g}" for n, r, b in zip(spec.variable_names, rest, near, strict=True) if r != b
    ]
    if not moved:
        return words
    where = "the joint limits" if robot_limits(kin) is not None else "the rest's sliders"
    return (
        f"{words}, the default, outside {where}: moving a rest slider sets the rest with "
        f"{', '.join(moved)}, the nearest values within them"
    )


def inverse_parameters(state: ChosenState, algorithm: str) -> dict[str, Any]:
    """What the engine's ``make_inverse`` takes for ``algorithm``: its scalars, and the posture
    inverse's rest when the state sets one."""
    names = REGISTRY[algorithm].names
    return {k: v for k, v in state.algorithm_parameters.items() if k in names}


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
            raise refused("algorithms", f"{a} cannot run on this robot: {exc}") from None


def cache_key(state: ChosenState, algorithm: str) -> str:
    """Everything one algorithm's run depends on: the state without what only a panel shows,
    the other algorithms' parameters, the map (but for the extended inverse) and gamma in
    continuous mode (see :mod:`jik.app.dashboard.results`)."""
    d = state.as_dict()
    d.pop("cspace_axes")  # (what a panel shows, not what is solved)
    d.pop("algorithms")
    d["algorithm_parameters"] = inverse_parameters(state, algorithm)
    d["algorithm"] = algorithm
    if algorithm != "extended":
        d.pop("augmentation"), d.pop("augmentation_parameters")
    if state.mode == "continuous":
        d.pop("gamma")
    return json.dumps(d, sort_keys=True)


def runs_key(state: ChosenState) -> tuple[str, ...]:
    """Everything the runs of the chosen algorithms depend on, up to the scale of theta (in
    continuous mode gamma only divides theta)."""
    return tuple(cache_key(state, a) for a in state.algorithms)
