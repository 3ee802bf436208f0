"""A request's robot built through one path, :func:`request_robot`: a catalogue robot and its
map by the registry; a definition of a kind of :mod:`jik.engine.robot_kinds` or a catalogue arm,
and its map (``{"name": "formula", "h": ...}`` or ``{"name": "e2_synthesized", ...}``), by
:func:`jik.engine.robot_spec.robot_from_dict` in a compute worker, within
``Settings.build_budget`` (a formula too slow to differentiate is refused naming the robot);
each with the inverses the request asks for; its vectors' lengths checked against the robot.
Each refusal is a :class:`RequestError` naming the request's field (the engine's renamed:
``lengths.1`` -> ``robot.lengths[1]``, ``augmentations.0.h`` -> ``augmentation.h``)."""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, cast

from pydantic import BaseModel

from ...engine.exceptions import InvalidInputError, JikError
from ...engine.inverses import ExtendedInverse
from ...engine.parameters import check_params
from ...engine.registry import ALGORITHMS, ROBOTS, RobotSpec, make_inverse
from ...engine.robot_spec import Robot, robot_from_dict
from ...engine.robot_synthesis import default_degree
from ...engine.solve_rules import gamma_problem
from ...engine.units import robot_units
from . import schemas as S
from .budget import build_seconds, time_budget
from .exceptions import RequestError
from .schemas.algorithms import field_of, used
from .schemas.wording import field_text, without_field


@dataclass(frozen=True)
class RequestRobot:
    """A request's robot, built: its spec and kinematics, the inverse of each algorithm asked
    for, what the response repeats (the robot used; the map the extended inverse used, else
    None), and a function building the request's map (else the robot's default) and what it
    used: the map h synthesis' 'evaluate' evaluates."""

    spec: RobotSpec
    kinematics: Any
    inverses: tuple[Any, ...]
    robot: S.RobotUsed
    augmentation: S.AugmentationUsed | None
    augmenting_map: Callable[[], tuple[Any, S.AugmentationUsed]]


def request_robot(
    req_robot: Any,
    augmentation: Any = None,
    algorithms: Sequence[str] = (),
    parameters: BaseModel | None = None,
    x0: Sequence[float] | None = None,
    *,
    own: bool = False,
    with_map: bool = False,
) -> RequestRobot:
    """The robot of a request (catalogue robot, definition or catalogue arm) and the inverse of
    each of ``algorithms``: the extended inverse (11) of ``augmentation`` (a map model; None:
    the robot's default), the others with ``parameters`` (``algorithm_parameters``; posture's
    rest defaults to the robot's home, else ``x0``), each with only its own if ``own`` (then a
    parameter of none of them is refused, :func:`_belong`). The
    robot has its map if the extended inverse or ``with_map`` asks for one; a map given to
    algorithms none of which is the extended inverse is refused; one given for no algorithm is
    checked all the same (a catalogue map's parameters, a formula map's formulas), except a map
    to synthesize. Refusals are :class:`RequestError` naming the request's field."""

    def given(algorithm: str) -> dict:
        names = ALGORITHMS[algorithm].names
        return {k: v for k, v in used(parameters).items() if not own or k in names}

    if own:
        _belong(used(parameters), algorithms)
    extended, aug_used = "extended" in algorithms, None
    if augmentation is not None and algorithms and not (extended or with_map):
        names = " and ".join(algorithms)
        takes = "inverses take" if len(algorithms) > 1 else "inverse takes"
        raise RequestError("augmentation", f"the {names} {takes} none (the extended inverse does)")
    if req_robot.name in S.USER_ROBOT_MODELS:
        # A formula map no chosen algorithm uses is built all the same, to be checked (its
        # formulas' derivatives, within the build budget); a map to synthesize is not.
        checked = extended or with_map or getattr(augmentation, "name", None) == "formula"
        robot, robot_used = user_robot(req_robot, augmentation if checked else None, x0)
        kin = robot.kinematics
        inverses = tuple(user_inverse(robot, a, given(a), x0) for a in algorithms)
        aug_used = map_used(robot) if extended else None
        built = robot.spec, kin, inverses, robot_used, aug_used
        return RequestRobot(*built, lambda: user_map(robot))
    spec, kin, robot_used = build_robot(req_robot)
    if augmentation is not None and not (extended or with_map):
        checked_augmentation(spec, augmentation)
    out: list[Any] = []
    for algorithm in algorithms:
        if algorithm == "extended":
            amap, aug_used = build_augmentation(spec, kin, augmentation)
            try:
                out.append(ExtendedInverse(kin, amap))
            except InvalidInputError as exc:
                raise RequestError("augmentation", str(exc)) from None
            continue
        try:
            params = given(algorithm)
            out.append(make_inverse(kin, algorithm, spec=spec, algorithm_parameters=params, x0=x0))
        except InvalidInputError as exc:
            raise RequestError(field_of(exc.field), without_field(str(exc), exc.field)) from None
    built = spec, kin, tuple(out), robot_used, aug_used
    return RequestRobot(*built, lambda: build_augmentation(spec, kin, augmentation))


def _belong(given: dict, algorithms: Sequence[str]) -> None:
    """Each parameter given belongs to at least one of the chosen ``algorithms`` (a run of
    several takes each its own, :func:`request_robot`'s ``own``), as a run of one refuses
    another's; each then goes to its algorithms, which check its value."""
    known = {name for a in algorithms for name in ALGORITHMS[a].names}
    for name in given:
        if name not in known:
            raise RequestError(
                f"algorithm_parameters.{name}",
                f"unknown parameter {name!r} for the algorithms {list(algorithms)}; "
                f"known: {sorted(known) or 'none'}",
            )


def build_robot(req_robot) -> tuple[RobotSpec, Any, S.RobotUsed]:
    """The catalogue robot of the request (its model names one), built with its parameters;
    what it used, filled in."""
    spec = ROBOTS[req_robot.name]
    params = req_robot.model_dump(exclude={"name"})
    try:
        kin = spec.build(**params)
    except (InvalidInputError, TypeError) as exc:
        raise RequestError("robot", str(exc)) from None
    used = {
        k: [float(t) for t in v] if isinstance(v, tuple | list) else float(v)
        for k, v in params.items()
    }
    units = S.UnitsInfo(**robot_units(kin, spec.task_names).summary())
    return spec, kin, S.RobotUsed(name=spec.name, title=spec.title, parameters=used, units=units)


def build_augmentation(spec: RobotSpec, kin, req_aug) -> tuple[Any, S.AugmentationUsed]:
    """The augmenting map named in the request (or the robot's default), built and checked;
    what it used."""
    aspec, values = checked_augmentation(spec, req_aug)
    try:
        amap = aspec.build(kin, **values)
    except InvalidInputError as exc:
        raise RequestError("augmentation", str(exc)) from None
    return amap, S.AugmentationUsed(name=aspec.name, parameters=values)


def checked_augmentation(spec: RobotSpec, req_aug) -> tuple[Any, dict]:
    """The map named in the request (or the robot's default) and its parameters' values, each
    checked against the map's :class:`~jik.engine.parameters.Parameter` (a map that no chosen
    algorithm uses is checked too: what the published schema refuses, the server refuses)."""
    name = req_aug.name if req_aug is not None else None
    try:
        aspec = spec.augmentation(name)
    except InvalidInputError as exc:
        raise RequestError("augmentation.name", str(exc)) from None
    given = req_aug.model_dump(exclude={"name"}, exclude_unset=True) if req_aug is not None else {}
    known = {p.name for p in aspec.parameters}
    unknown = sorted(set(given) - known)
    if unknown:
        raise RequestError(
            f"augmentation.{unknown[0]}",
            f"{aspec.name} of {spec.name} has no parameter {unknown[0]!r}; "
            f"its parameters: {sorted(known) or 'none'}",
        )
    values = {p.name: given.get(p.name, p.default) for p in aspec.parameters}
    try:
        check_params(aspec.parameters, values, f"{aspec.name} of {spec.name}")
    except InvalidInputError as exc:
        raise RequestError("augmentation", str(exc)) from None
    return aspec, values


def length_problem(spec: RobotSpec, what: str, got: int) -> str | None:
    """Why a vector of ``got`` components is not one of the robot's p (``what`` "p") or r
    components (``p of manipulator2``; a user robot's p and r), or None if it is."""
    n = spec.p if what == "p" else spec.r
    if got == n:
        return None
    why = f"{what} of {spec.name}"
    if spec.name in S.USER_ROBOT_MODELS:
        why = f"this {spec.name} robot has p = {spec.p}, r = {spec.r}"
    return f"must have {n} components ({why}), got {got}"


def check_length(spec: RobotSpec, vector, field: str, what: str = "r") -> None:
    """The request's vector at ``field`` has the robot's r (``what`` "p": p) components."""
    if (problem := length_problem(spec, what, len(vector))) is not None:
        raise RequestError(field, problem)


def gamma_and_mode(spec: RobotSpec, req) -> tuple[float, S.Mode]:
    """The request's gamma of eq. (5) and mode, the robot's where not given; RequestError at
    ``gamma`` when it does not suit the mode (:func:`~jik.engine.solve_rules.gamma_problem`)."""
    mode = req.mode or spec.default_mode
    gamma = spec.default_gamma if req.gamma is None else float(req.gamma)
    if (why := gamma_problem(gamma, mode)) is not None:
        raise RequestError("gamma", why)
    return gamma, mode


#: The augmentation's label inside the built robot.
_LABEL = "request"


def request_field(field: str | None, robot_keys: Sequence[str]) -> str:
    """The request's field for a field of the engine's definition (as the module says)."""
    parts = (field or "").split(".")
    if parts[0] == "augmentations":
        parts = ["augmentation", *parts[2:]]
    elif parts[0] == "augmenting_maps":  # (a vector of maps, VectorExtendedInverse's argument)
        parts = ["augmentation"]
    elif parts[0] in robot_keys:
        parts = ["robot", *parts]
    elif parts[0] != "augmentation":
        return "robot"
    return field_text(".".join(parts))  # (indices as the API writes them: robot.task[0])


def built(definition: Mapping[str, Any]) -> Robot:
    """The robot of a definition, kept (keyed by its JSON text): a worker serving the same
    robot again, a dashboard's scene and figures, reuse its kinematics and any synthesized map
    (the engine's InvalidInputError, naming the definition's field, when it is refused)."""
    return _built(json.dumps(dict(definition), sort_keys=True))


@functools.lru_cache(maxsize=32)
def _built(definition: str) -> Robot:
    return robot_from_dict(json.loads(definition))


def user_robot(
    req_robot: Any, augmentation: Any = None, start: Sequence[float] | None = None
) -> tuple[Robot, S.RobotUsed]:
    """The robot a request defines, with ``augmentation`` (a request's map model, or None) as
    its only augmenting map; what it used. RequestError, naming the request's field, when the
    engine refuses the definition or the map. A definition takes no x0: where the engine
    refuses its default start (a task undefined there and across its box, as log(x1 - 100)),
    the request's ``start`` (its x0) is the robot's start if given."""
    definition = req_robot.model_dump(exclude_none=True)
    if augmentation is not None:
        given = augmentation.model_dump(exclude_none=True)
        definition["augmentations"] = [{**given, "label": _LABEL}]
    try:
        with time_budget(build_seconds(), "robot", "building the robot's formulas"):
            robot = built(definition)
    except InvalidInputError as exc:
        started = _started(definition, start) if exc.field == "x0" else None
        if started is None:
            raise RequestError(request_field(exc.field, list(definition)), _text(exc)) from None
        robot = started
    spec = robot.spec
    used = S.RobotUsed(
        name=spec.name,
        title=spec.title,
        parameters={},
        definition=echo(req_robot.model_dump(exclude_none=True)),
        p=spec.p,
        r=spec.r,
        notes=list(getattr(robot.kinematics, "notes", ())) or None,
        units=S.UnitsInfo(**robot.units.summary()),
    )
    return robot, used


def _started(definition: dict, start: Sequence[float] | None) -> Robot | None:
    """The robot of ``definition`` started at ``start``; None without one, or if the engine
    refuses that too (the first refusal is then the one to report)."""
    if start is None:
        return None
    try:
        with time_budget(build_seconds(), "robot", "building the robot's formulas"):
            return built({**definition, "x0": [float(v) for v in start]})
    except InvalidInputError:
        return None


def map_used(robot: Robot) -> S.AugmentationUsed | None:
    """The map the robot's extended inverse uses (the request's, else the robot's default, e.g.
    a catalogue arm's E2 synthesis), as defined with its defaults filled in (an e2_synthesized
    map's region and degree); None for a robot without one."""
    items = [a for a in robot.definition.get("augmentations", []) if isinstance(a, dict)]
    if not items:
        return None
    item = next((a for a in items if a.get("label") == _LABEL), items[0])
    definition = {k: v for k, v in item.items() if k != "label"}
    if definition["name"] == "e2_synthesized" and "degree" not in definition:
        variables, k = len(definition.get("region") or {}), robot.spec.p - robot.spec.r
        definition["degree"] = default_degree(variables, k)
    values = {k: float(v) for k, v in (definition.get("parameters") or {}).items()}
    return S.AugmentationUsed(name=definition["name"], parameters=values, definition=definition)


def echo(definition: dict) -> dict:
    """A definition as a response repeats it: a URDF's text is left out (it can be 100 kB, and
    a response is no place to mirror what a client sent), named by its size and SHA-256."""
    if not isinstance(definition.get("urdf"), str):
        return definition
    data = definition["urdf"].encode("utf-8")
    rest = {k: v for k, v in definition.items() if k != "urdf"}
    return {**rest, "urdf_bytes": len(data), "urdf_sha256": hashlib.sha256(data).hexdigest()}


def _text(exc: InvalidInputError) -> str:
    """The engine's message without a leading field name, ``field: ...`` or ``field must ...``
    (the RequestError adds the request's name of the field)."""
    return without_field(str(exc), exc.field)


def user_inverse(robot: Robot, algorithm: str, algorithm_parameters: dict | None = None, x0=None):
    """The robot's inverse: the extended inverse (11) of its map, or another algorithm with
    its parameters (the pseudoinverse (8), damped, weighted, posture; ``x0`` the run's start,
    posture's default rest for a robot without home)."""
    try:
        if algorithm != "extended":
            return robot.inverse(algorithm, algorithm_parameters=algorithm_parameters, x0=x0)
        given = _LABEL in {a.name for a in robot.spec.augmentations}
        return robot.inverse(algorithm, _LABEL if given else None)  # (else the robot's default)
    except InvalidInputError as exc:
        if algorithm != "extended":
            raise RequestError(field_of(exc.field), _text(exc)) from None
        raise RequestError(request_field(exc.field, ()), _text(exc)) from None


def user_map(robot: Robot) -> tuple[Any, S.AugmentationUsed]:
    """The map h a user robot's 'evaluate' request gives, built (for p - r >= 2 the tuple of
    its p - r maps, a synthesis made here); what it used."""
    spec = robot.spec
    if not spec.augmentations:
        raise RequestError(
            "augmentation",
            "'evaluate' needs the map to evaluate: {'name': "
            "'formula', 'h': ...} or {'name': 'e2_synthesized', 'region': {...}}",
        )
    amap: Any
    try:
        if spec.p > spec.r + 1:
            vector = robot.map_vectors[spec.augmentations[0].name]
            amap = tuple(vector() if callable(vector) else vector)
        else:
            amap = spec.augmentations[0].build(robot.kinematics)
    except JikError as exc:
        raise RequestError(request_field(getattr(exc, "field", None), ()), str(exc)) from None
    return amap, cast(S.AugmentationUsed, map_used(robot))  # (the robot has a map: above)
