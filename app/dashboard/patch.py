"""A change of the dashboard's state as a request body: :data:`StatePatch` (the state's fields,
all optional, and control keys such as ``x0.1``), checked by :func:`parse_patch` and
:func:`patch_of`; what depends on the robot is checked when the patch is applied
(:func:`jik.app.dashboard.model.updated_state`).
"""

from __future__ import annotations

import re
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError, create_model

from ...engine.exceptions import InvalidInputError
from ...engine.registry import ROBOTS
from ...engine.repeatability import MAX_PATH_POINTS
from ..compute.schemas import AUGMENTATION_MODELS, USER_AUGMENTATION_MODELS, Coordinate
from ..compute.schemas.wording import refusal, refused
from .algorithms import check_names
from .model import DashboardState, Number, Numbers, Point, error_location
from .robots import USER_KINDS

#: Control keys a patch may hold besides the state's fields (:func:`.control_changes.expand`), and
#: their values: one coordinate of ``x0``, ``target`` or the posture inverse's rest, one
#: parameter of the robot (a number or a vector), of the map or of an algorithm, the rest whole
#: or at the start ("x0"). (The first pattern a key matches gives its type.)
CONTROL_KEYS: dict[str, Any] = {
    r"^(?:x0|target|algorithm_parameters\.rest)\.[0-9]+$": Coordinate,
    r"^algorithm_parameters\.rest$": Numbers | Literal["x0"],
    r"^robot_parameters\.[A-Za-z_][A-Za-z0-9_]*$": Number | Point,
    r"^augmentation_parameters\.[A-Za-z_][A-Za-z0-9_]*$": Number,
    r"^algorithm_parameters\.[A-Za-z_][A-Za-z0-9_]*$": Number,
}
_PATCH_TYPES: dict[str, Any] = {
    "robot": Literal[(*ROBOTS, *USER_KINDS)],
    "augmentation": Literal[(*AUGMENTATION_MODELS, *USER_AUGMENTATION_MODELS)],
    "robot_parameters": dict[str, float | Point],
    "augmentation_parameters": dict[str, float],
    "path": Annotated[tuple[Point, ...], Field(max_length=MAX_PATH_POINTS)]
    | Annotated[str, Field(max_length=10_000)],
}


def _patch_model() -> type[BaseModel]:
    fields: dict[str, Any] = {}
    for name, info in DashboardState.model_fields.items():
        annotation = _PATCH_TYPES.get(name)
        if annotation is None:
            annotation = info.annotation
            for meta in info.metadata:
                annotation = Annotated[annotation, meta]
        fields[name] = (annotation, Field(None, description=f"the state's {name}"))
    return create_model(
        "StatePatch",
        __config__=ConfigDict(
            extra="allow",
            json_schema_extra={
                "patternProperties": {
                    key: TypeAdapter(kind).json_schema() for key, kind in CONTROL_KEYS.items()
                },
                "additionalProperties": False,
                "examples": [{"robot": "manipulator1"}, {"gamma": 2.0, "x0.1": 0.5}],
            },
        ),
        __doc__="A change of the dashboard's state: some of its fields, and control keys "
        "(``x0.1``, ``robot_parameters.l``: one coordinate or parameter); ``path`` may be text "
        "('x, y; x, y; ...'). Checked against the session's robot when applied.",
        **fields,
    )


#: The body of a change (``POST /api/sessions/{id}/state``, a link's state): the state's fields
#: with their types, all optional; what depends on the robot is checked by :func:`updated_state`.
StatePatch = _patch_model()


def parse_patch(body: Any) -> dict[str, Any]:
    """A change's JSON body as a patch (:data:`StatePatch`, then :func:`patch_of`).

    Raises
    ------
    InvalidInputError
        Naming the field: the first the patch's types refuse (a member of a union, labelled by
        its type in pydantic's location, is left out of the name: :func:`error_location`).
    """
    if isinstance(body, dict) and isinstance(names := body.get("algorithm_parameters"), dict):
        check_names(names)  # (before the types: a name's refusal says what it is)
    try:
        return patch_of(StatePatch.model_validate(body))
    except ValidationError as exc:
        errors = exc.errors()
        # (of a union's refusals, the one of the member the value is: a text path too long is
        # that, not "should be a valid tuple")
        same = [e for e in errors if e["loc"][:1] == errors[0]["loc"][:1]]
        error = next((e for e in same if not e["type"].endswith("_type")), same[0])
        field = ".".join(error_location(body, error)) or "body"
        raise refused(field, refusal(error)) from None


def patch_of(patch: BaseModel) -> dict[str, Any]:
    """The fields a :data:`StatePatch` was given, and its control keys (checked here: a key of
    no known form, or a value not of its type, is refused naming the key)."""
    controls = {}
    for key, value in (patch.model_extra or {}).items():
        kind = next((k for p, k in CONTROL_KEYS.items() if re.match(p, key)), None)
        if kind is None:
            raise InvalidInputError(f"unknown dashboard control {key!r}", key)
        try:
            controls[key] = TypeAdapter(kind).validate_python(value)
        except ValidationError as exc:
            raise refused(key, refusal(exc.errors()[0])) from None
    return {**patch.model_dump(exclude_unset=True), **controls}
