"""``POST /kinematics``: k(x) and J(x) of any robot at one configuration or a list of them, to
check a model against other tools: the same robots as ``/solve``, the engine's kinematics, eq.
(4), and its analytic Jacobian, in a compute worker (:func:`kinematics_task`)."""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...engine.arms import ARMS
from . import schemas as S
from .documents import nullable
from .robot_requests import check_length, request_robot
from .schemas.fields import coordinates, one_or_many
from .schemas.variants import per_robot
from .worker import task

#: Most configurations one request evaluates.
MAX_CONFIGURATIONS = 1000


def _many(one: Any) -> Any:
    return Annotated[list[one], Field(min_length=1, max_length=MAX_CONFIGURATIONS)]


class KinematicsRequest(BaseModel):
    """k(x) and J(x) of a robot at x: one configuration, or a list of them."""

    model_config = ConfigDict(extra="forbid")

    robot: S.AnyRobot = Field(
        description="the robot, as for /solve: e.g. {'name': 'panda', 'task': 'pose'}"
    )
    x: one_or_many(S.Vector, _many(S.Vector)) = Field(  # type: ignore[valid-type]
        description=f"one configuration (p numbers) or a list of 1 to {MAX_CONFIGURATIONS}"
    )


def _points(p: int | None) -> Any:
    """x: one configuration of p numbers (1 to 16 when p is known only once the robot is
    built), or a list of them."""
    one = coordinates(p) if p else S.Vector
    return (
        one_or_many(one, _many(one)),
        Field(
            description=f"one configuration ({p or 'p'} numbers) or a list of 1 to "
            f"{MAX_CONFIGURATIONS}"
        ),
    )


#: ``POST /kinematics``'s body: a :class:`KinematicsRequest` whose x has its robot's p where the
#: robot's name fixes it (the paper's robots, the catalogue arms), chosen by ``robot.name``.
KinematicsBody = per_robot(
    KinematicsRequest,
    lambda spec: {"x": _points(spec.p)},
    lambda kind: {"x": _points(len(ARMS[kind].home) if kind in ARMS else None)},
)


class KinematicsResponse(BaseModel):
    robot: S.RobotUsed
    variable_names: list[str] = Field(description="the p configuration variables, in x's order")
    task_names: list[str] = Field(description="the r task coordinates, in k's order")
    k: list[float | None] | list[list[float | None]] = Field(
        description="k(x): r numbers, or one row per configuration (null where not finite)"
    )
    J: list[list[float | None]] | list[list[list[float | None]]] = Field(
        description="J(x) = dk/dx: r rows of p, or one such matrix per configuration (a row "
        "null where its k is not: a derivative of an undefined coordinate is none)"
    )


@task("x", "fewer configurations or a simpler robot")
def kinematics_task(body: bytes) -> bytes:
    """The worker's task: a request (JSON) in, its robot built and its k and J at its x, the
    response (JSON) out; raises :class:`RequestError`."""
    req = KinematicsRequest.model_validate_json(body)
    many = isinstance(req.x[0], list)
    robot = request_robot(req.robot, x0=req.x[0] if many else req.x)
    spec, kin = robot.spec, robot.kinematics
    for i, row in enumerate(req.x if many else [req.x]):
        check_length(spec, row, f"x[{i}]" if many else "x", "p")
    x = np.asarray(req.x, dtype=float)
    k, J = kin.forward_jacobian(x)
    J = np.where(np.isfinite(k)[..., None], J, np.nan)  # (log(x1) at x1 = -1: no dk/dx either)
    response = KinematicsResponse(
        robot=robot.robot,
        variable_names=list(spec.variable_names),
        task_names=list(spec.task_names),
        k=nullable(k),
        J=nullable(J),
    )
    return response.model_dump_json().encode()
