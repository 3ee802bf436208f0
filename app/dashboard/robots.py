"""The robot of a dashboard state: one of the paper's (``robot``, with ``robot_parameters``), or
a kind of :mod:`jik.engine.robot_kinds` or a catalogue arm with its definition
(``robot_definition``). Every part of the dashboard asks here for the state's
:class:`~jik.engine.registry.RobotSpec`, its kinematics and its inverses, so the two cases differ
in this module only. A definition's refusal names its field under ``robot_definition``
(``robot_definition.lengths.1``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...engine.arms import ARMS
from ...engine.exceptions import InvalidInputError
from ...engine.inverses import Inverse
from ...engine.kinematics import Kinematics
from ...engine.registry import RobotSpec, robot_spec
from ...engine.robot_defaults import kept_variables
from ...engine.robot_kinds import KINDS
from ...engine.robot_spec import Robot
from ..compute.budget import build_seconds, time_budget
from ..compute.exceptions import RequestError
from ..compute.robot_requests import built
from ..compute.schemas.wording import refused, without_field
from ..compute.worker import task
from .algorithms import inverse_parameters

#: The robots given by a definition: the kinds a user defines (the editor's choices), and the
#: catalogue's arms (:mod:`jik.engine.arms`), whose definition is their name and task.
USER_KINDS = (*KINDS, *ARMS)


def default_definition(robot: str) -> dict[str, Any] | None:
    """The definition a robot starts with when chosen by name: a catalogue arm's
    ``{"name": arm, "task": its default task}``; None for a kind the user defines."""
    return {"name": robot, "task": ARMS[robot].task} if robot in ARMS else None


def _built(definition: Mapping[str, Any]) -> Robot:
    robot = built(definition)
    spec = robot.spec
    if spec.augmentations or spec.p <= spec.r:
        return robot
    kept = [spec.variable_names[i] for i in kept_variables(robot.kinematics, spec.default_x0)]
    h = kept[0] if len(kept) == 1 else kept
    return built({**definition, "augmentations": [{"name": "formula", "h": h}]})


def user_robot(definition: Mapping[str, Any]) -> Robot:
    """The robot of a definition (kept: the worker, the scene and the figures share it), with
    an augmenting map added when it has none: h = the last variable (p = r + 1), or the last
    p - r variables, so that the extended inverse has a map.

    Raises
    ------
    InvalidInputError
        With ``field`` under ``robot_definition``.
    """
    try:
        return _built(definition)
    except InvalidInputError as exc:
        field = f"robot_definition.{exc.field}" if exc.field else "robot_definition"
        raise refused(field, without_field(str(exc), exc.field)) from None


@task("robot_definition", "shorter formulas or fewer nested functions")
def check_definition(definition: Mapping[str, Any]) -> None:
    """Build a definition as :func:`user_robot` does, with the second derivatives that the
    characteristics of section 4 take, within the build budget (a compute worker's task);
    :class:`RequestError` naming its field if it is refused."""
    what = "building the robot's formulas"
    with time_budget(build_seconds(), "robot_definition", what):
        try:
            kinematics = _built(definition).kinematics
            hessian = getattr(kinematics, "hessian", None)
            if hessian is not None:
                hessian(np.zeros((1, kinematics.p)))
        except InvalidInputError as exc:
            field = "robot_definition" + (f".{exc.field}" if exc.field else "")
            raise RequestError(field, without_field(str(exc), exc.field)) from None


async def vet_definition(pool: Any, patch: Mapping[str, Any]) -> None:
    """Build the robot definition a change brings (``patch["robot_definition"]``) in ``pool``
    (a :class:`~jik.app.compute.pool.ComputePool`) first, off the event loop and within its
    limits; nothing to do for a change without one.

    Raises
    ------
    InvalidInputError
        Naming the field under ``robot_definition`` (the whole definition when its build ran
        out of time).
    """
    definition = patch.get("robot_definition")
    if not isinstance(definition, Mapping) or pool is None:
        return
    try:
        await pool.run(check_definition, dict(definition))
    except RequestError as exc:
        raise refused(exc.field, exc.message) from None


def state_robot(state, kin: Kinematics | None = None) -> Robot:
    """The robot of a state: its definition's (:func:`user_robot`), or the catalogue robot
    built with its parameters (its kinematics ``kin`` if given)."""
    definition = getattr(state, "robot_definition", None)
    if definition is not None:
        return user_robot(definition)
    spec, parameters = robot_spec(state.robot), dict(state.robot_parameters)
    kin = spec.build(**parameters) if kin is None else kin
    return Robot(spec, kin, {"name": spec.name, "parameters": parameters})


def state_spec(state) -> RobotSpec:
    """The spec of a state's robot: p, r, names, ranges, defaults and augmenting maps (a
    catalogue robot's without building its kinematics)."""
    definition = getattr(state, "robot_definition", None)
    return robot_spec(state.robot) if definition is None else user_robot(definition).spec


def state_kinematics(state) -> Kinematics:
    """The kinematics of a state's robot, with its parameters."""
    return state_robot(state).kinematics


def state_inverse(state, algorithm: str, kin: Kinematics | None = None) -> Inverse:
    """The state's inverse for ``algorithm``: its map and the map's parameters, or the
    algorithm's own (:func:`jik.app.dashboard.algorithms.inverse_parameters`; the posture
    inverse's default rest at the state's start x0)."""
    robot = state_robot(state, kin)
    params = inverse_parameters(state, algorithm)
    extended = algorithm == "extended"  # (the map is the extended inverse's alone)
    return robot.inverse(
        algorithm,
        state.augmentation if extended else None,
        state.augmentation_parameters if extended else None,
        algorithm_parameters=params,
        x0=state.x0,
    )
