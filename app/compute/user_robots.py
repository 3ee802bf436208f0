"""A request's user robot (a definition of a kind of :mod:`jik.engine.robot_kinds`, or a
catalogue arm) and its map (``{"name": "formula", "h": ...}`` or ``{"name": "e2_synthesized",
...}``), built by :func:`jik.engine.robot_spec.robot_from_dict` in a compute worker, within
``Settings.build_budget`` (a formula too slow to differentiate is refused naming the robot);
each refusal's field renamed to the request's (``lengths.1`` -> ``robot.lengths[1]``,
``augmentations.0.h`` -> ``augmentation.h``). The half of
:func:`jik.app.compute.robot_requests.request_robot` for these robots.
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Mapping, Sequence
from typing import Any, cast

from ...engine.exceptions import InvalidInputError, JikError
from ...engine.robot_spec import Robot, robot_from_dict
from ...engine.robot_synthesis import default_degree
from . import schemas as S
from .budget import build_seconds, time_budget
from .exceptions import RequestError
from .schemas.algorithms import field_of
from .schemas.wording import field_text, without_field

#: The augmentation's label inside the built robot.
_LABEL = "request"


def request_field(field: str | None, robot_keys: Sequence[str]) -> str:
    """The request's field for a field of the engine's definition (see the module docstring)."""
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


def user_robot(req_robot: Any, augmentation: Any = None) -> tuple[Robot, S.RobotUsed]:
    """The robot a request defines, with ``augmentation`` (a request's map model, or None) as
    its only augmenting map; what it used. RequestError, naming the request's field, when the
    engine refuses the definition or the map."""
    definition = req_robot.model_dump(exclude_none=True)
    if augmentation is not None:
        given = augmentation.model_dump(exclude_none=True)
        definition["augmentations"] = [{**given, "label": _LABEL}]
    try:
        with time_budget(build_seconds(), "robot", "building the robot's formulas"):
            robot = built(definition)
    except InvalidInputError as exc:
        raise RequestError(request_field(exc.field, list(definition)), _text(exc)) from None
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
    """The one map h a user robot's 'evaluate' request gives, built; what it used."""
    spec = robot.spec
    if not spec.augmentations:
        raise RequestError(
            "augmentation",
            "'evaluate' needs the map to evaluate: {'name': "
            "'formula', 'h': ...} or {'name': 'e2_synthesized', 'region': {...}}",
        )
    if spec.p != spec.r + 1:
        raise RequestError(
            "augmentation",
            f"'evaluate' takes one map h and E1, E2 need p = r + 1; this {spec.name} robot has "
            f"p = {spec.p}, r = {spec.r}",
        )
    try:
        amap = spec.augmentations[0].build(robot.kinematics)
    except JikError as exc:
        raise RequestError(request_field(getattr(exc, "field", None), ()), str(exc)) from None
    return amap, cast(S.AugmentationUsed, map_used(robot))  # (the robot has a map: above)
