"""A request's catalogue robot and augmenting map, built by the registry; its vectors' lengths
checked against the robot. Each refusal is a :class:`RequestError` naming the request's field."""

from __future__ import annotations

from typing import Any

from ...engine.exceptions import InvalidInputError
from ...engine.registry import ROBOTS, RobotSpec
from . import schemas as S
from .exceptions import RequestError


def build_robot(req_robot) -> tuple[RobotSpec, Any, S.RobotUsed]:
    """The robot named in the request, built with its parameters; what it used, filled in."""
    try:
        spec = ROBOTS[req_robot.name]
    except KeyError:
        raise RequestError(
            "robot.name", f"unknown robot {req_robot.name!r}; choose one of {sorted(ROBOTS)}"
        ) from None
    params = req_robot.model_dump(exclude={"name"})
    try:
        kin = spec.build(**params)
    except (InvalidInputError, TypeError) as exc:
        raise RequestError("robot", str(exc)) from None
    used = {
        k: [float(t) for t in v] if isinstance(v, tuple | list) else float(v)
        for k, v in params.items()
    }
    return spec, kin, S.RobotUsed(name=spec.name, parameters=used)


def build_augmentation(spec: RobotSpec, kin, req_aug):
    """The augmenting map named in the request (or the robot's default), built and checked."""
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
        amap = aspec.build(kin, **values)
    except InvalidInputError as exc:
        raise RequestError("augmentation", str(exc)) from None
    return aspec, amap, S.AugmentationUsed(name=aspec.name, parameters=values)


def _dimensions(spec: RobotSpec, what: str) -> str:
    """Why a vector has its length: ``p of manipulator2``; a user robot's p and r."""
    if spec.name in S.USER_ROBOT_MODELS:
        return f"this {spec.name} robot has p = {spec.p}, r = {spec.r}"
    return f"{what} of {spec.name}"


def check_configuration(spec: RobotSpec, x0) -> None:
    """The robot has at most the API's p, and ``x0`` has p components."""
    if spec.p > S.MAX_DIMENSION:
        joints = (
            "; name at most that many in active_joints (the others stay at their value in "
            "locked, default 0)"
            if spec.name == "urdf"
            else ""
        )
        raise RequestError(
            "robot",
            f"this {spec.name} robot has p = {spec.p} moving joints; the API takes at "
            f"most {S.MAX_DIMENSION} (the cap on x0's components){joints}",
        )
    if len(x0) != spec.p:
        raise RequestError(
            "x0", f"must have {spec.p} components ({_dimensions(spec, 'p')}), got {len(x0)}"
        )


def check_task_point(spec: RobotSpec, y, name: str) -> None:
    """The task point ``y`` (the request's field ``name``) has r components."""
    if len(y) != spec.r:
        raise RequestError(
            name, f"must have {spec.r} components ({_dimensions(spec, 'r')}), got {len(y)}"
        )
