"""The dashboard's state: every control, validated against the registry and the engine.

A change (:func:`updated_state`) is a patch of state fields or of control keys
(:func:`jik.app.dashboard.control_changes.expand`); each refusal names its field
(:attr:`jik.engine.exceptions.InvalidInputError.field`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ...engine.exceptions import InvalidInputError
from ...engine.registry import ROBOTS, robot_spec
from ...engine.repeatability import MAX_PATH_POINTS
from ...engine.solve_rules import gamma_problem
from ..compute.schemas import (
    AUGMENTATION_MODELS,
    INTEGRAL,
    MAX_DIMENSION,
    MAX_ITERATIONS_CAP,
    ROBOT_MODELS,
    Coordinate,
    FreeObject,
    Gamma,
    Mode,
    Tolerance,
)
from ..compute.schemas.algorithms import Algorithm
from ..compute.schemas.wording import field_text, refusal, refused, without_field
from .algorithms import (
    CHOICES,
    DEFAULT_ALGORITHMS,
    check_inverses,
    check_names,
    checked,
    checked_rest,
)
from .control_changes import expand
from .controls import MAX_DASHBOARD_CYCLES, MIN_ITERATIONS, max_iterations
from .robots import USER_KINDS, default_definition, state_inverse, state_spec, user_robot

DEFAULT_ROBOT = "manipulator2"

Point = Annotated[tuple[Coordinate, ...], Field(min_length=1, max_length=MAX_DIMENSION)]
#: A number given as one (not as text), and up to MAX_DIMENSION of them.
Number = Annotated[float, Field(strict=True)]
Numbers = Annotated[tuple[Number, ...], Field(max_length=MAX_DIMENSION)]
#: An algorithm's parameter: a number, or a vector (the posture inverse's rest, checked with the
#: robot: :func:`jik.app.dashboard.algorithms.checked_rest`).
AlgorithmValue = Number | Numbers


class DashboardState(BaseModel):
    """Every control of the dashboard, with the types and bounds of a REST request's fields
    (:mod:`jik.app.compute.schemas`: the same ``gamma``, ``mode``, ``tolerance``, coordinates
    and path); the robot's and the map's parameters are checked by the same per-robot and
    per-map models as a request's ``robot`` and ``augmentation``.

    ``task``: "path", the closed path driven ``cycles`` times; "target", one solve.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    robot: str
    robot_parameters: dict[str, Any]
    #: A robot given by a definition (:mod:`jik.app.dashboard.robots`), whose ``name`` is
    #: ``robot``: a kind of :mod:`jik.engine.robot_kinds` or a catalogue arm; None for the
    #: paper's robots.
    robot_definition: FreeObject | None = None
    augmentation: str
    augmentation_parameters: dict[str, Any]
    gamma: Gamma
    mode: Mode
    x0: Point
    task: Literal["path", "target"]
    target: Point
    path: Annotated[tuple[Point, ...], Field(max_length=MAX_PATH_POINTS)]
    cycles: Annotated[int, Field(strict=True, ge=1, le=MAX_DASHBOARD_CYCLES), INTEGRAL]
    tolerance: Tolerance = 1e-10
    #: The three coordinates the configuration-space panel shows (p > 3), their indices as
    #: hexadecimal digits in increasing order: "012" is x1, x2, x3, "06a" x1, x7, x11.
    cspace_axes: Annotated[str, Field(pattern=r"^[0-9a-f]{3}$")] | None = None
    #: Cap on each leg's iterations (discrete) or integrator steps (continuous); None: the
    #: engine's default (:func:`jik.engine.solver.solve`).
    max_iterations: (
        Annotated[int, Field(strict=True, ge=MIN_ITERATIONS, le=MAX_ITERATIONS_CAP), INTEGRAL]
        | None
    ) = None
    #: The inverses run side by side, and the parameters of those chosen
    #: (:mod:`jik.app.dashboard.algorithms`): numbers, and the posture inverse's ``rest``.
    algorithms: Annotated[tuple[Algorithm, ...], Field(min_length=1, max_length=len(CHOICES))] = (
        DEFAULT_ALGORITHMS
    )
    algorithm_parameters: dict[str, AlgorithmValue] = {}

    def as_dict(self) -> dict:
        """The state as JSON data (tuples as lists)."""
        return self.model_dump(mode="json")


#: The fields of a state that say which robot and map it has (a user's robot by its definition).
ROBOT_AND_MAP = (
    "robot",
    "robot_parameters",
    "robot_definition",
    "augmentation",
    "augmentation_parameters",
)


def robot_and_map(state: DashboardState) -> dict:
    """The state's :data:`ROBOT_AND_MAP` fields, as JSON data."""
    d = state.as_dict()
    return {k: d[k] for k in ROBOT_AND_MAP}


def default_state(
    robot: str = DEFAULT_ROBOT, definition: Mapping[str, Any] | None = None
) -> DashboardState:
    """The registry's defaults for ``robot``; for a user robot, its definition's start, target,
    path and first map. A platform (the unicycle) starts with the paper's experiment of
    sec. 6.2: one target."""
    user = definition is not None or robot in USER_KINDS
    if user:
        definition = _user_definition(robot, definition)
        spec = _redundant_robot(definition).spec
    else:
        spec = robot_spec(robot)
    aug = spec.augmentation(None)
    closed = bool(spec.default_path) and spec.default_path_loops
    params: dict[str, object] = {p.name: p.default for p in spec.parameters}
    params.update({v.name: tuple(v.default) for v in spec.vector_parameters})
    try:
        return DashboardState(
            robot=spec.name,
            robot_parameters=params,
            robot_definition=dict(definition) if definition is not None else None,
            augmentation=aug.name,
            augmentation_parameters={p.name: p.default for p in aug.parameters},
            gamma=float(spec.default_gamma),
            mode=spec.default_mode,
            x0=tuple(float(v) for v in spec.default_x0),
            task="path" if closed else "target",
            target=tuple(float(v) for v in spec.default_target),
            path=tuple(tuple(float(v) for v in p) for p in spec.default_path),
            cycles=3 if closed else 1,
        )
    except ValidationError as exc:
        if not user:
            raise
        # Defaults the robot computes (its target k(x0), its path) outside the dashboard's
        # ranges: the definition is what the user can change.
        first = exc.errors()[0]
        where = field_text(".".join(str(p) for p in first["loc"]))
        head = str(first["loc"][0])
        value = first.get("input")
        shown = f"{value:.4g}" if isinstance(value, float | int) else f"{value!r:.40}"
        fields = ", ".join(k for k in definition or {} if k != "name")
        raise refused(
            "robot_definition",
            f"the robot's default {head}{' k(x0)' if head == 'target' else ''} has {where} = "
            f"{shown}, which the dashboard refuses ({first['msg']}); change the definition "
            f"({fields})",
        ) from None


def _user_definition(robot: str, definition: Mapping[str, Any] | None) -> Mapping[str, Any]:
    """The definition of a user robot of kind ``robot``: the one given, else a catalogue arm's
    own (:func:`~jik.app.dashboard.robots.default_definition`); refused naming its field."""
    definition = default_definition(robot) if definition is None else definition
    if not isinstance(definition, Mapping):
        raise refused(
            "robot_definition", f"a {robot} robot needs its definition (the robot editor's fields)"
        )
    if definition.get("name") != robot:
        problem = f"must be the robot's kind {robot!r}, got {definition.get('name')!r}"
        raise refused("robot_definition.name", problem)
    return definition


def updated_state(state: DashboardState, patch: Mapping[str, object]) -> DashboardState:
    """Apply a partial change and validate the result (:func:`validate`).

    ``patch`` is keyed by state fields or by control keys (:func:`.control_changes.expand`:
    ``{"x0.1": 0.4}``, ``{"path": "1, 1; 1, 2"}``). Changing ``robot`` starts from that robot's
    defaults; changing ``augmentation`` resets its parameters to their defaults. Nested
    parameter dicts are merged.

    Raises
    ------
    InvalidInputError
        An unknown field, or a value the models, the registry or the engine refuse; its
        ``field`` names the field (a dotted path).
    """
    robot = patch.get("robot", state.robot)
    definition = patch.get("robot_definition", state.robot_definition)
    if definition is not None and not isinstance(definition, Mapping):
        raise refused("robot_definition", "give an object (the robot editor's fields)")
    if robot != state.robot or definition != state.robot_definition:
        if not isinstance(robot, str) or robot not in (*ROBOTS, *USER_KINDS):
            known = f"{sorted(ROBOTS)} or a kind {list(USER_KINDS)}"
            raise refused("robot", f"unknown robot {robot!r}; choose one of {known}")
        if robot != state.robot and "robot_definition" not in patch:
            definition = None  # (another robot chosen: the definition was the other's)
        # (the chosen algorithms and their numbers stay: the new robot's defaults are for
        # everything else, the posture inverse's rest included)
        state = default_state(robot, definition).model_copy(
            update={
                "algorithms": state.algorithms,
                "algorithm_parameters": {
                    k: v for k, v in state.algorithm_parameters.items() if k != "rest"
                },
            }
        )
    # (control keys after a change of robot are the new robot's: {"robot": "unicycle",
    # "x0.0": 0} changes the unicycle's x0, not the old robot's)
    patch = expand(state, patch)
    data = state.as_dict()
    if "augmentation" in patch and patch["augmentation"] != data["augmentation"]:
        spec = state_spec(state)
        aug = _registered(lambda: spec.augmentation(str(patch["augmentation"])), "augmentation")
        data["augmentation"] = aug.name
        data["augmentation_parameters"] = {p.name: p.default for p in aug.parameters}
    for key, value in patch.items():
        if key in ("robot", "augmentation", "robot_definition"):
            continue
        if key in ("robot_parameters", "augmentation_parameters", "algorithm_parameters"):
            if not isinstance(value, Mapping):
                raise refused(key, "give an object of parameters")
            value = {**data[key], **value}
            if value.get("rest", ()) is None:  # (the posture rest's default: none set)
                del value["rest"]
        data[key] = value
    return validate(data)


def validate(data: Mapping[str, Any]) -> DashboardState:
    """A state from ``data``, checked as a REST request is: the model's types and bounds, the
    robot's and the map's parameters by their request models, then what needs the robot (its
    kinematics built, vector lengths p and r, gamma < 2 in discrete mode).

    Raises
    ------
    InvalidInputError
        With the first refused field as ``field`` and the message starting with it.
    """
    if isinstance(names := data.get("algorithm_parameters"), Mapping):
        check_names(names)  # (before the model's types: a name's refusal says what it is)
    state = _model(DashboardState, data, ())
    if state.robot_definition is not None or state.robot in USER_KINDS:
        spec, kin, params, aug_params = _user_robot(state)
    else:
        spec = _registered(lambda: robot_spec(state.robot), "robot")
        params = _model(
            ROBOT_MODELS[spec.name],
            {**state.robot_parameters, "name": spec.name},
            ("robot_parameters",),
        ).model_dump(exclude={"name"})
        aug = _registered(lambda: spec.augmentation(state.augmentation), "augmentation")
        aug_params = _model(
            AUGMENTATION_MODELS[aug.name],
            {**state.augmentation_parameters, "name": aug.name},
            ("augmentation_parameters",),
        ).model_dump(exclude={"name"})
        kin = _registered(lambda: spec.build(**params), "robot_parameters")
    _registered(lambda: kin.check(state.x0, "x0"), "x0")
    _registered(lambda: kin.check_target(state.target, "target"), "target")
    if state.path:
        _registered(lambda: kin.check_target(state.path, "path"), "path")
    elif state.task == "path":
        raise InvalidInputError("path: a closed-path task needs at least one path point", "path")
    if (why := gamma_problem(state.gamma, state.mode)) is not None:
        raise InvalidInputError(f"gamma: {why}", "gamma")
    if state.cspace_axes is not None:
        a, b, c = (int(k, 16) for k in state.cspace_axes)
        if not a < b < c < kin.p:
            raise refused("cspace_axes", f"give three of x1..x{kin.p} in increasing order")
    given = state.algorithm_parameters
    # (a rest is checked whether or not the posture inverse is chosen; kept only if it is)
    rest = checked_rest(given["rest"], spec, kin, state.x0) if "rest" in given else None
    state = state.model_copy(update=checked(state.algorithms, given))
    if "rest" in state.algorithm_parameters:
        chosen = dict(state.algorithm_parameters)
        del chosen["rest"]
        if rest is not None:
            chosen["rest"] = rest
        state = state.model_copy(update={"algorithm_parameters": chosen})
    check_inverses(state, lambda a: state_inverse(state, a, kin))
    # The engine's default cap, set by its value, is the default (None): it follows the mode.
    default_cap = max_iterations(state.model_copy(update={"max_iterations": None}))
    return state.model_copy(
        update={
            "max_iterations": None if state.max_iterations == default_cap else state.max_iterations,
            # (the first three coordinates are the default, and all there is for p = 3)
            "cspace_axes": None if state.cspace_axes == "012" or kin.p < 4 else state.cspace_axes,
            "robot_parameters": {
                k: tuple(v) if isinstance(v, list | tuple) else v for k, v in params.items()
            },
            "augmentation_parameters": aug_params,
        }
    )


def _user_robot(state: DashboardState) -> tuple[Any, Any, dict, dict]:
    """Spec, kinematics and (empty) parameters of a state's user robot, its map checked."""
    definition = state.robot_definition
    if state.robot in ROBOTS or definition is None:
        raise InvalidInputError(
            "robot_definition: only a user robot (robot one of "
            f"{list(USER_KINDS)}) has a definition; {state.robot!r} needs it "
            + ("removed" if definition is not None else "given"),
            "robot_definition",
        )
    for key in ("robot_parameters", "augmentation_parameters"):
        if getattr(state, key):
            raise refused(key, "a user robot has none")
    robot = _redundant_robot(_user_definition(state.robot, definition))
    _registered(lambda: robot.spec.augmentation(state.augmentation), "augmentation")
    return robot.spec, robot.kinematics, {}, {}


#: The field of a definition that sets its number of joint variables p, by kind.
JOINTS_FIELD = {"planar_chain": "joints", "formula": "variables", "urdf": "active_joints"}


def _redundant_robot(definition: Mapping[str, Any]):
    """The user robot of ``definition`` if the dashboard shows it: task paths in a plane or
    space (r >= 2) and redundancy (p > r; the h panel draws one scalar h, p = r + 1, and says
    so otherwise). Refused naming the field that sets p."""
    robot = user_robot(definition)
    p, r = robot.spec.p, robot.spec.r
    if r < 2 or p <= r:
        field = f"robot_definition.{JOINTS_FIELD.get(str(definition.get('name')), 'name')}"
        raise InvalidInputError(
            f"{field}: the dashboard needs a redundant robot with r >= 2 task components, "
            f"p > r; this robot has p = {p}, r = {r} (the REST API and jik solve take it)",
            field,
        )
    return robot


def _model(model: type[BaseModel], data: Mapping[str, Any], prefix: tuple[str, ...]) -> Any:
    """``model`` validating ``data``; its first error as an :class:`InvalidInputError` naming
    the field (``prefix`` and the error's location, dotted)."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        error = exc.errors()[0]
        name = ".".join((*prefix, *error_location(data, error))) or "state"
        raise refused(name, refusal(error)) from None


def error_location(data: Any, error: Mapping[str, Any]) -> list[str]:
    """The field of one of pydantic's errors in ``data``: the keys and indices of its location,
    without the labels pydantic gives the members of a union (``algorithm_parameters.rest``,
    not ``algorithm_parameters.rest.float``): a name that is not a key of the value it is
    under (a missing field's excepted) or is under a value without fields."""
    parts, node = [], data
    for part in error["loc"]:
        if isinstance(node, list | tuple) and isinstance(part, int):
            node = node[part] if part < len(node) else None
        elif isinstance(node, Mapping) and (part in node or error.get("type") == "missing"):
            node = node.get(part)
        elif isinstance(part, str):
            continue
        parts.append(str(part))
    return parts


def _registered(check, name: str):
    """``check()``; an engine's or the registry's refusal as a refusal of field ``name`` (of
    ``robot_parameters.l`` for the parameter ``l`` the registry names)."""
    try:
        return check()
    except InvalidInputError as exc:
        field = exc.field or name
        if name.endswith("_parameters") and exc.field:
            field = f"{name}.{exc.field}"
        raise refused(field, without_field(str(exc), exc.field or name)) from None
