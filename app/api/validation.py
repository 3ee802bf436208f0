"""Pydantic's validation errors as the API reports them: each names its field (``robot.l``,
``x0[2]``) at the start of its message, without the labels of union members, and a vector of the
wrong length says how many components the request's robot needs and why."""

from __future__ import annotations

from ...engine.registry import ROBOTS
from ..compute.robot_requests import length_problem
from ..compute.schemas import (
    AUGMENTATION_MODELS,
    ROBOT_MODELS,
    ROBOT_NAMES,
    USER_AUGMENTATION_MODELS,
    USER_ROBOT_MODELS,
)
from ..compute.schemas.wording import field_text, refusal

_TAGS = {*ROBOT_MODELS, *AUGMENTATION_MODELS, *USER_ROBOT_MODELS, *USER_AUGMENTATION_MODELS}
#: The tags of a request's variants: the catalogue robots and the kinds of user robots.
_VARIANTS = set(ROBOT_NAMES)
_TYPE_LABELS = {"str", "float", "int", "bool", "constrained-float", "constrained-str"}


def _field(loc) -> str:
    """Field path of a location (:func:`_location`'s): ``["body", "robot", "l"]`` -> ``robot.l``.

    Indices become ``x0[2]``; the discriminator tag of a robot's or a map's name is dropped.
    """
    parts = [str(p) for p in loc if p != "body"]
    if len(parts) > 2 and parts[0] in ("robot", "augmentation") and parts[1] in _TAGS:
        del parts[1]
    return field_text(".".join(parts)) or "body"


def _location(loc) -> list:
    """A pydantic location without the labels of union members that are not fields: the
    request's robot variant (``("body", "manipulator2", "x0")``) and a member labelled by its
    type (``("body", "path", "str")``)."""
    out = [p for p in loc if not (isinstance(p, str) and (p in _TYPE_LABELS or "[" in p))]
    if len(out) > 2 and out[0] == "body" and out[1] in _VARIANTS:
        del out[1]
    return out


def validation_detail(errors) -> list[dict]:
    """FastAPI's list of errors, ``{"loc", "msg", "type"}``, each message naming its field."""
    detail = []
    for e in errors:
        kind, ctx = e.get("type"), e.get("ctx") or {}
        loc = _location(e.get("loc", ()))
        msg = refusal(e)
        if kind == "json_invalid":  # (loc: the body and the character's position)
            where = f" at character {loc[1]}" if len(loc) > 1 else ""
            loc, msg = ["body"], f"not valid JSON{where}: {ctx.get('error', msg)}"
        elif kind == "union_tag_invalid":
            msg = f"unknown name {ctx.get('tag')!r}; choose one of {ctx.get('expected_tags')}"
        elif kind == "unknown_robot":  # (the request's variant, chosen by robot.name)
            loc = [*loc, "robot"]
            body = e.get("input")
            robot = body.get("robot") if isinstance(body, dict) else None
            name = robot.get("name") if isinstance(robot, dict) else None
            if isinstance(body, dict) and "robot" not in body:
                msg = "Field required"
            elif isinstance(robot, str):  # (the command line's and load_robot's way to name one)
                known = robot if robot in ROBOT_NAMES else ROBOT_NAMES[0]
                msg = (
                    f'must be an object such as {{"name": "{known}"}}, not the string '
                    f"{robot[:40]!r}; names: {ROBOT_NAMES}"
                )
            elif name is None:
                msg = f"give the robot, with a name among {ROBOT_NAMES}"
            else:
                msg = f"unknown name {name!r}; choose one of {ROBOT_NAMES}"
        elif kind in ("too_short", "too_long"):
            msg = _length_message(e.get("loc", ()), ctx) or msg
        detail.append({"loc": loc, "msg": f"{_field(loc)}: {msg}", "type": str(kind)})
    return detail


#: Vectors whose length is the robot's p (the others: r); path and shifts hold points.
_CONFIGURATIONS = ("x0", "reference")
_TASK_VECTORS = ("target", "path", "shifts")


def _length_message(loc, ctx: dict) -> str | None:
    """A vector of the wrong length for the request's robot (its tag is the location's second
    part): how many components it needs and why."""
    parts = [str(p) for p in loc]
    spec = ROBOTS.get(parts[1]) if len(parts) > 2 else None
    if spec is None or parts[2] not in (*_CONFIGURATIONS, *_TASK_VECTORS):
        return None
    if parts[2] in ("path", "shifts") and len(parts) < 4:
        return None  # (the list of points itself)
    what = "p" if parts[2] in _CONFIGURATIONS else "r"
    return length_problem(spec, what, ctx.get("actual_length", -1))
