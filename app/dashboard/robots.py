"""The robot of a dashboard state: one of the catalogue, or one the user defined.

A state names a catalogue robot (``robot``, with ``robot_parameters``), or a kind of
:mod:`jik.engine.robot_kinds` with its definition (``robot_definition``, built by
:func:`jik.engine.robot_spec.robot_from_dict`). Every part of the dashboard asks here for the
state's :class:`~jik.engine.registry.RobotSpec`, its kinematics and its inverses, so the two
cases differ in this module only. A definition's refusal names its field under
``robot_definition`` (``robot_definition.lengths.1``), which the page's robot editor shows next
to the field.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping
from typing import Any

from jik.engine.exceptions import InvalidInputError
from jik.engine.inverses import Inverse
from jik.engine.kinematics import Kinematics
from jik.engine.registry import RobotSpec, make_inverse, robot_spec
from jik.engine.robot_kinds import KINDS
from jik.engine.robot_spec import Robot, robot_from_dict

#: The kinds of robots a user defines (the editor's choices besides the catalogue).
USER_KINDS = tuple(KINDS)


@functools.lru_cache(maxsize=32)
def _built(definition: str) -> Robot:
    robot = robot_from_dict(json.loads(definition))
    spec = robot.spec
    if spec.augmentations or spec.p <= spec.r:
        return robot
    last = list(spec.variable_names[spec.r :])
    h = last[0] if len(last) == 1 else last
    return robot_from_dict({**json.loads(definition), "augmentations": [{"name": "formula",
                                                                         "h": h}]})  # fmt: skip


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
        return _built(json.dumps(dict(definition), sort_keys=True))
    except InvalidInputError as exc:
        field = f"robot_definition.{exc.field}" if exc.field else "robot_definition"
        text = str(exc)
        raise InvalidInputError(f"{field}: {text}" if not text.startswith(field) else text,
                                field) from None  # fmt: skip


def state_robot(state) -> Robot | None:
    """The user robot of a state (None for a catalogue robot)."""
    definition = getattr(state, "robot_definition", None)
    return None if definition is None else user_robot(definition)


def state_spec(state) -> RobotSpec:
    """The spec of a state's robot: p, r, names, ranges, defaults and augmenting maps."""
    robot = state_robot(state)
    return robot_spec(state.robot) if robot is None else robot.spec


def state_kinematics(state) -> Kinematics:
    """The kinematics of a state's robot, with its parameters."""
    robot = state_robot(state)
    if robot is None:
        return robot_spec(state.robot).build(**state.robot_parameters)
    return robot.kinematics


def state_inverse(state, algorithm: str, kin: Kinematics | None = None) -> Inverse:
    """The state's inverse for ``algorithm``: its map and the map's parameters."""
    robot = state_robot(state)
    if robot is not None:
        return robot.inverse(algorithm, state.augmentation)
    spec = robot_spec(state.robot)
    kin = spec.build(**state.robot_parameters) if kin is None else kin
    return make_inverse(
        kin, algorithm, state.augmentation, state.augmentation_parameters, spec.name
    )
