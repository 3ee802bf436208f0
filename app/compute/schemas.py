"""Request and response models of the REST API (JSON, snake_case).

(It stays whole, at about 400 lines: the API's one description of its requests and responses,
read top to bottom as the OpenAPI document is.)

Robot and augmentation models are generated from the engine's catalogue
(:data:`jik.engine.registry.ROBOTS`) when this module is imported: one model per robot with its
parameters and their ranges, discriminated by ``name``, and one per augmenting map. A robot or map
the catalogue gains appears in the API, its OpenAPI schema and the fuzz test with no change here.

Pydantic checks types, ranges, finiteness (``allow_inf_nan=False``: NaN and inf are rejected) and
size bounds. What needs the registry (vector lengths against p and r, an augmentation that belongs
to the robot, a singular start) is checked by :mod:`jik.app.compute.requests`, which names the
field. The dashboard's state (:mod:`jik.app.dashboard.model`) uses the same field types and the
same robot and map models.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeAlias, Union

from pydantic import BaseModel, BeforeValidator, ConfigDict, Discriminator, Field, Tag, create_model

from jik.app.compute.algorithm_schemas import Algorithm as Algorithm
from jik.app.compute.algorithm_schemas import AlgorithmParameters
from jik.engine.registry import ROBOTS, AugmentationSpec, RobotSpec
from jik.engine.repeatability import MAX_CYCLES, MAX_PATH_POINTS
from jik.engine.solver import DISCRETE_GAMMA_BOUND, GAMMA_MAX, GAMMA_MIN, TOL_MIN

#: Largest configuration / task dimension accepted before the registry check.
MAX_DIMENSION = 16
#: Largest step / iteration cap a request may ask for.
MAX_ITERATIONS = 20000
#: Trajectories longer than this are downsampled (first and last points kept).
MAX_TRAJECTORY_POINTS = 2000

FiniteFloat = Annotated[float, Field(strict=True, allow_inf_nan=False)]


def _integral(value: Any) -> Any:
    """A float with no fraction is the integer it equals (JSON Schema's "integer": 49.0 is one)."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


#: Makes a strict ``int`` take what JSON Schema calls an integer (49 or 49.0), never a boolean
#: or a string: ``Annotated[int, Field(strict=True, ...), INTEGRAL]`` (after the
#: Field, or the schema loses its bounds).
INTEGRAL = BeforeValidator(_integral)


#: A float that is null where the engine produced NaN or inf (a failed or diverged run).
MaybeFloat = float | None


def _camel(name: str) -> str:
    return "".join(part.capitalize() for part in name.replace("-", "_").split("_"))


def _scalar_field(p) -> tuple[Any, Any]:
    extra = " (nonzero)" if p.nonzero else ""
    return (
        Annotated[
            float,
            Field(
                strict=True,
                ge=p.minimum,
                le=p.maximum,
                allow_inf_nan=False,
                description=f"{p.description}{extra}; default {p.default:g}",
            ),
        ],
        p.default,
    )


def _vector_field(v) -> tuple[Any, Any]:
    items = tuple(
        Annotated[float, Field(strict=True, ge=lo, le=hi, allow_inf_nan=False)]
        for lo, hi in zip(v.minimum, v.maximum, strict=True)
    )
    return (
        # The item types are built at runtime (one per coordinate): a dynamic type by design.
        Annotated[tuple[items], Field(description=f"{v.description}; default {list(v.default)}")],  # type: ignore[valid-type]
        tuple(v.default),
    )


def _robot_model(spec: RobotSpec) -> type[BaseModel]:
    fields: dict[str, Any] = {"name": (Literal[spec.name], ...)}
    for p in spec.parameters:
        fields[p.name] = _scalar_field(p)
    for v in spec.vector_parameters:
        fields[v.name] = _vector_field(v)
    return create_model(
        f"{_camel(spec.name)}Robot",
        __config__=ConfigDict(extra="forbid", title=spec.title),
        __doc__=f"{spec.title}: {spec.description}, eq. {spec.equation}.",
        **fields,
    )


def _augmentation_model(name: str, specs: list[AugmentationSpec]) -> type[BaseModel]:
    fields: dict[str, Any] = {"name": (Literal[name], ...)}
    for spec in specs:
        for p in spec.parameters:
            fields.setdefault(p.name, _scalar_field(p))
    first = specs[0]
    return create_model(
        f"{_camel(name)}Augmentation",
        __config__=ConfigDict(extra="forbid"),
        __doc__=f"Augmenting map {name}, eq. {first.equation}: {first.description}.",
        **fields,
    )


def _union(models: list[type[BaseModel]]) -> Any:
    if len(models) == 1:
        return models[0]
    return Annotated[Union[tuple(models)], Field(discriminator="name")]  # noqa: UP007


ROBOT_MODELS: dict[str, type[BaseModel]] = {name: _robot_model(s) for name, s in ROBOTS.items()}
_by_name: dict[str, list[AugmentationSpec]] = {}
for _spec in ROBOTS.values():
    for _a in _spec.augmentations:
        _by_name.setdefault(_a.name, []).append(_a)
AUGMENTATION_MODELS: dict[str, type[BaseModel]] = {
    name: _augmentation_model(name, specs) for name, specs in _by_name.items()
}
for _m in (*ROBOT_MODELS.values(), *AUGMENTATION_MODELS.values()):
    globals()[_m.__name__] = _m  # importable by name (pickling, introspection)

Mode = Literal["continuous", "discrete"]
#: Largest |coordinate| of a configuration or task point (radians, lengths, control amplitudes):
#: beyond it the kinematics only overflow, and the unicycle's quadrature would need huge grids.
COORDINATE_BOUND = 1000.0
Coordinate = Annotated[
    float, Field(strict=True, ge=-COORDINATE_BOUND, le=COORDINATE_BOUND, allow_inf_nan=False)
]
Vector = Annotated[list[Coordinate], Field(min_length=1, max_length=MAX_DIMENSION)]
#: The decay rate of eq. (5) (discrete mode: the step; its bound there is checked with the mode,
#: engine.solver.gamma_problem).
Gamma = Annotated[float, Field(strict=True, ge=GAMMA_MIN, le=GAMMA_MAX, allow_inf_nan=False)]
#: The task error at which a solve stops.
Tolerance = Annotated[float, Field(strict=True, ge=TOL_MIN, le=1.0, allow_inf_nan=False)]


# --------------------------------------------------------------------------------------------
# Robots defined by data (issue 29): the kinds of jik.engine.robot_kinds, checked in full by
# jik.engine.robot_spec.robot_from_dict. The schema says what JSON Schema can (names, sizes,
# the joints' letters); the formulas' grammar, the URDF text and what follows from them (p, r,
# the lengths of x0, target and path) are checked when the robot is built, naming the field.

#: Longest formula text (the engine's bound, :data:`jik.engine.formula.MAX_LENGTH`).
MAX_FORMULA_CHARS = 2000
#: Longest URDF text a request carries [characters]: a tenth of the 1 MiB body limit, room for
#: an arm of dozens of links (the shipped 4-joint arm is 2 kB). A larger file goes through the
#: CLI (``jik solve --robot arm.json`` with ``urdf_file``; the engine's bound is 1 MB). At 1 MB
#: here, schemathesis's negative cases (a string one longer) took it past 17 GB of memory.
MAX_URDF_CHARS = 100_000
#: A variable's, a parameter's or a joint's name.
Name = Annotated[str, Field(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,31}$")]
FormulaText = Annotated[str, Field(min_length=1, max_length=MAX_FORMULA_CHARS)]
Constants = Annotated[dict[Name, FiniteFloat], Field(max_length=32)]
Title = Annotated[str, Field(min_length=1, max_length=100)]
_USER = ConfigDict(extra="forbid")


class PlanarChainRobot(BaseModel):
    """A planar serial chain of revolute (R) and prismatic (P) joints: the end point (r = 2),
    or the end point and its angle (r = 3); p is the number of joints."""

    model_config = ConfigDict(extra="forbid", title="Planar chain")
    name: Literal["planar_chain"]
    joints: Annotated[str, Field(pattern=r"^[RP]{1,16}$")] = Field(
        description="joint types, base first: R revolute, P prismatic (p = its length)"
    )
    lengths: Annotated[list[Coordinate], Field(min_length=1, max_length=MAX_DIMENSION)] = Field(
        description="link lengths, one per joint"
    )
    offsets: Annotated[list[Coordinate], Field(min_length=1, max_length=MAX_DIMENSION)] | None = (
        Field(None, description="joint offsets added to x, one per joint (default 0)")
    )
    orientation: Annotated[bool, Field(strict=True)] = Field(
        False, description="also the end's angle as a task component (r = 3; needs p >= 3)"
    )
    title: Title | None = None


class FormulaRobot(BaseModel):
    """Kinematics written as formulas: k(x) = (task[0], task[1], ...) in the variables."""

    model_config = ConfigDict(extra="forbid", title="Formula robot")
    name: Literal["formula"]
    variables: Annotated[list[Name], Field(min_length=1, max_length=MAX_DIMENSION)] = Field(
        description="joint variable names, in order (p = their number)"
    )
    task: Annotated[list[FormulaText], Field(min_length=1, max_length=MAX_DIMENSION)] = Field(
        description="task components (r = their number): formulas in the variables and "
        "parameters with sin cos tan exp log sqrt atan2 abs, + - * / **, numbers and pi"
    )
    parameters: Constants = Field(default_factory=dict, description="named constants")
    title: Title | None = None


class UrdfRobot(BaseModel):
    """A serial arm from URDF text: the end link's position (task 'xyz' or a subset)."""

    model_config = ConfigDict(extra="forbid", title="URDF arm")
    name: Literal["urdf"]
    urdf: Annotated[str, Field(min_length=1, max_length=MAX_URDF_CHARS)] = Field(
        description="the URDF text (no DOCTYPE; meshes are not loaded)"
    )
    end_link: Annotated[str, Field(min_length=1, max_length=200)] = Field(
        description="the link whose origin is the end point"
    )
    active_joints: (
        Annotated[
            list[Annotated[str, Field(min_length=1, max_length=200)]],
            Field(min_length=1, max_length=MAX_DIMENSION),
        ]
        | None
    ) = Field(None, description="the joints that move (default: all from the base to end_link)")
    task: Literal["xyz", "xy", "xz", "yz", "x", "y", "z"] = Field(
        "xyz", description="coordinates of the end point"
    )
    locked: Annotated[
        dict[Annotated[str, Field(min_length=1, max_length=200)], FiniteFloat],
        Field(max_length=64),
    ] = Field(default_factory=dict, description="values of the chain's other movable joints")
    title: Title | None = None


class FormulaMapAugmentation(BaseModel):
    """An augmenting map h written as a formula in the robot's variables, eq. (9); for
    p - r > 1 a list of p - r formulas (the extended inverse of several maps)."""

    model_config = ConfigDict(extra="forbid", title="Formula map")
    name: Literal["formula"]
    h: FormulaText | Annotated[list[FormulaText], Field(min_length=1, max_length=15)] = Field(
        description="h(x), e.g. 'x3'; a list of p - r formulas when p - r > 1"
    )
    parameters: Constants | None = Field(None, description="named constants of h")


class E2SynthesisAugmentation(BaseModel):
    """The E2-optimal map on a box, synthesized by the Ritz solve of eq. (20) (p = r + 1)."""

    model_config = ConfigDict(extra="forbid", title="E2-synthesized map")
    name: Literal["e2_synthesized"]
    region: Annotated[
        dict[Name, tuple[Annotated[float, Field(strict=True, ge=-100.0, le=100.0,
                                                allow_inf_nan=False)],
                         Annotated[float, Field(strict=True, ge=-100.0, le=100.0,
                                                allow_inf_nan=False)]]],
        Field(min_length=2, max_length=3),
    ] = Field(description="two or three variables to [lo, hi], lo < hi")  # fmt: skip
    degree: Annotated[int, Field(strict=True, ge=1, le=24), INTEGRAL] = Field(
        12, description="Legendre degree per variable"
    )
    fixed: Annotated[dict[Name, FiniteFloat], Field(max_length=MAX_DIMENSION)] | None = Field(
        None, description="values of the variables outside the box (default 0)"
    )


#: The robots a user defines, by kind (their ``name``).
USER_ROBOT_MODELS: dict[str, type[BaseModel]] = {
    "planar_chain": PlanarChainRobot,
    "formula": FormulaRobot,
    "urdf": UrdfRobot,
}
#: The augmenting maps a user robot takes, by name.
USER_AUGMENTATION_MODELS: dict[str, type[BaseModel]] = {
    "formula": FormulaMapAugmentation,
    "e2_synthesized": E2SynthesisAugmentation,
}
#: Every robot name a request may give: the catalogue's, then the kinds of user robots.
ROBOT_NAMES = [*ROBOTS, *USER_ROBOT_MODELS]
UserAugmentation = Annotated[
    FormulaMapAugmentation | E2SynthesisAugmentation, Field(discriminator="name")
]

if TYPE_CHECKING:
    # Generated from the catalogue at import time (above), so their fields are invisible to a
    # static checker: type them as Any there.
    Robot: TypeAlias = Any
    Augmentation: TypeAlias = Any
    AnyRobot: TypeAlias = Any
    AnyAugmentation: TypeAlias = Any
else:
    #: A catalogue robot and one of its maps (what the atlas takes).
    Robot = _union(list(ROBOT_MODELS.values()))
    Augmentation = _union(list(AUGMENTATION_MODELS.values()))
    #: Any robot and map of a solve, repeatability or synthesis: the base request models, which
    #: the workers validate with, take them all; the routes take the exact per-robot members
    #: of :func:`per_robot`.
    AnyRobot = _union([*ROBOT_MODELS.values(), *USER_ROBOT_MODELS.values()])
    AnyAugmentation = Augmentation | UserAugmentation


class _Request(BaseModel):
    model_config = ConfigDict(extra="forbid")

    robot: AnyRobot = Field(
        description="the robot and its parameters, e.g. {'name': 'manipulator2', 'l': 1}"
    )
    algorithm: Algorithm = Field(
        description="'pseudoinverse' (eq. (8)), 'extended' (extended Jacobian inverse, eq. (11)), "
        "'damped' (damped least squares), 'weighted' (weighted least-norm inverse for joint "
        "limits) or 'posture' (pseudoinverse with a null-space pull to a rest posture)"
    )
    algorithm_parameters: AlgorithmParameters | None = Field(
        None,
        description="parameters of the algorithm (damping, damping_threshold; limits; gain, "
        "rest); default: the engine's (GET /robots lists them)",
    )
    augmentation: AnyAugmentation | None = Field(
        None,
        description="augmenting map h of the extended inverse with its parameters; "
        "default: the robot's default augmentation (ignored by the pseudoinverse)",
    )
    x0: Vector = Field(description="start configuration, length p of the robot")
    gamma: Gamma | None = Field(
        None,
        description=f"decay rate > 0 of eq. (5) (discrete: the step, < {DISCRETE_GAMMA_BOUND:g}); "
        "default: the robot's",
    )
    mode: Mode | None = Field(
        None, description="'continuous' (ODE) or 'discrete' (iterations); default: the robot's"
    )
    tolerance: Tolerance = Field(1e-10, description="stop when ||k(x) - target|| < tolerance")
    max_iterations: Annotated[int, Field(strict=True, ge=1, le=MAX_ITERATIONS), INTEGRAL] | None = (
        Field(
            None,
            description="cap on integrator steps (continuous) or iterations (discrete) per solve",
        )
    )


class SolveRequest(_Request):
    """One run of the continuation algorithm (7) from x0 to a target task point."""

    target: Vector = Field(description="target task point, length r of the robot")


class RepeatabilityRequest(_Request):
    """Drive the robot ``cycles`` times around a closed task-space path (Table 1)."""

    path: Annotated[list[Vector], Field(min_length=1, max_length=MAX_PATH_POINTS)] = Field(
        description=f"task points visited in order, 1 to {MAX_PATH_POINTS}; k(x0) closes it"
    )
    cycles: Annotated[int, Field(strict=True, ge=1, le=MAX_CYCLES), INTEGRAL] = Field(
        1, description=f"1 to {MAX_CYCLES}"
    )


def _absent(value: Any) -> bool:
    """A response's field that only user robots have is left out for the catalogue's."""
    return value is None


class AugmentationUsed(BaseModel):
    """The augmenting map a run used, with every parameter (defaults filled in)."""

    name: str
    parameters: dict[str, float]
    definition: dict[str, Any] | None = Field(
        default=None,
        exclude_if=_absent,
        description="a user robot's map as given (absent otherwise)",
    )


class RobotUsed(BaseModel):
    """The robot a run used, with every parameter (defaults filled in)."""

    name: str
    parameters: dict[str, float | list[float]]
    definition: dict[str, Any] | None = Field(
        default=None,
        exclude_if=_absent,
        description="a user robot's definition as given (absent for a catalogue robot)",
    )
    p: int | None = Field(default=None, exclude_if=_absent, description="a user robot's p")
    r: int | None = Field(default=None, exclude_if=_absent, description="a user robot's r")


class Trajectory(BaseModel):
    """The run point by point (accepted integrator steps or iterations)."""

    theta: list[MaybeFloat] = Field(description="continuation parameter, or iteration number")
    x: list[list[MaybeFloat]] = Field(description="configurations, shape (m, p)")
    y: list[list[MaybeFloat]] = Field(description="k(x), shape (m, r)")
    error: list[MaybeFloat] = Field(description="||k(x) - target||, shape (m,)")
    h: list[MaybeFloat] | None = Field(None, description="h(x) for the extended inverse")
    points: int = Field(description="points of the full trajectory before downsampling")
    downsampled: bool


class SolveResponse(BaseModel):
    robot: RobotUsed
    algorithm: Algorithm
    augmentation: AugmentationUsed | None
    mode: Mode
    gamma: float
    tolerance: float
    x: list[MaybeFloat] = Field(
        description="final configuration (null entries if the run diverged)"
    )
    y: list[MaybeFloat] = Field(description="k(x)")
    error: MaybeFloat = Field(description="||k(x) - target||")
    converged: bool
    message: str
    iterations: int = Field(description="integrator steps or iterations taken")
    trajectory: Trajectory


class RepeatabilityResponse(BaseModel):
    robot: RobotUsed
    algorithm: Algorithm
    augmentation: AugmentationUsed | None
    mode: Mode
    gamma: float
    cycles: int
    targets: list[list[float]] = Field(description="task point of each leg of one cycle (closed)")
    legs: list[list[MaybeFloat]] = Field(
        description="configuration after each leg, all cycles (null after a failed leg)"
    )
    cycle_end: list[list[MaybeFloat]] = Field(description="configuration at the end of each cycle")
    drift: list[MaybeFloat] = Field(description="||cycle_end[c] - x0|| per cycle")
    max_drift: MaybeFloat
    repeatable: bool = Field(description="every leg succeeded and max drift < 1e-6")
    success: bool
    message: str


def _task_point(spec: RobotSpec) -> Any:
    r = len(spec.task_names)
    return Annotated[list[Coordinate], Field(min_length=r, max_length=r)]


def _robot_name(body: Any) -> str | None:
    """The robot's name in a request body (raw JSON data or a model): the variant to check."""
    robot = body.get("robot") if isinstance(body, dict) else getattr(body, "robot", None)
    name = robot.get("name") if isinstance(robot, dict) else getattr(robot, "name", None)
    return name if isinstance(name, str) else None


def per_robot(base: type[BaseModel], fields: Any, user_robots: bool = True) -> Any:
    """``base`` made exact for each robot of the catalogue: one model per robot, chosen by
    ``robot.name``, whose ``robot`` and ``augmentation`` are that robot's and whose vectors have
    its lengths (``fields(spec)``: the fields that differ from ``base``'s), and one per kind of
    user robot unless not ``user_robots``. Their union is what the route takes and what its
    OpenAPI document shows; each member is still a ``base``."""
    members = []
    names = ROBOT_NAMES if user_robots else list(ROBOTS)
    for name, spec in ROBOTS.items():
        augmentations = list(dict.fromkeys(a.name for a in spec.augmentations))
        model = create_model(
            f"{base.__name__.removesuffix('Request')}{_camel(name)}Request",
            __base__=base,
            __doc__=f"{(base.__doc__ or '').strip()} ({spec.title})",
            robot=(ROBOT_MODELS[name], Field(description=f"{spec.title} and its parameters")),
            **fields(spec, _union([AUGMENTATION_MODELS[a] for a in augmentations])),
        )
        globals()[model.__name__] = model
        members.append(Annotated[model, Tag(name)])
    for kind, robot_model in USER_ROBOT_MODELS.items() if user_robots else ():
        # p and r follow from the definition: the vectors keep the base's 1 to 16 components,
        # checked against the built robot (a 422 naming the field and the robot's p, r).
        model = create_model(
            f"{base.__name__.removesuffix('Request')}{_camel(kind)}Request",
            __base__=base,
            __doc__=f"{(base.__doc__ or '').strip()} ({robot_model.model_config.get('title')})",
            robot=(robot_model, Field(description=f"{robot_model.__doc__}")),
            augmentation=(
                UserAugmentation | None,
                Field(None, description="augmenting map h of the extended inverse: "
                      "{'name': 'formula', 'h': ...} or {'name': 'e2_synthesized', 'region': "
                      "{...}} (p = r + 1)" + USER_AUGMENTATION_NOTE.get(base.__name__, "")),
            ),
        )  # fmt: skip
        globals()[model.__name__] = model
        members.append(Annotated[model, Tag(kind)])
    return Annotated[
        Union[tuple(members)],  # noqa: UP007
        Discriminator(
            _robot_name,
            custom_error_type="unknown_robot",
            custom_error_message=f"give a robot whose name is one of {names}",
            custom_error_context={"names": str(names)},
        ),
    ]


#: What the augmentation of a user robot's request is for, by request.
USER_AUGMENTATION_NOTE = {
    "SynthesizeRequest": "; 'evaluate' needs one, 'e2_variational' takes none",
}


def _run_fields(spec: RobotSpec, augmentation: Any) -> dict[str, Any]:
    return {
        "augmentation": (
            augmentation | None,
            Field(
                None,
                description=f"augmenting map h of the extended inverse (one of "
                f"{sorted({a.name for a in spec.augmentations})}); default: "
                f"{spec.augmentation(None).name} (ignored by the pseudoinverse)",
            ),
        ),
        "x0": (
            Annotated[list[Coordinate], Field(min_length=spec.p, max_length=spec.p)],
            Field(description=f"start configuration {list(spec.variable_names)}"),
        ),
    }


#: ``POST /solve``'s body: a :class:`SolveRequest` with the lengths of its robot.
SolveBody = per_robot(
    SolveRequest,
    lambda spec, aug: {
        **_run_fields(spec, aug),
        "target": (_task_point(spec), Field(description=f"target {list(spec.task_names)}")),
    },
)
#: ``POST /repeatability``'s body: a :class:`RepeatabilityRequest` with its robot's lengths.
RepeatabilityBody = per_robot(
    RepeatabilityRequest,
    lambda spec, aug: {
        **_run_fields(spec, aug),
        "path": (
            Annotated[list[_task_point(spec)], Field(min_length=1, max_length=MAX_PATH_POINTS)],  # type: ignore[misc]
            Field(
                description=f"task points {list(spec.task_names)} visited in order, 1 to "
                f"{MAX_PATH_POINTS}; k(x0) closes it"
            ),
        ),
    },
)


class ParameterInfo(BaseModel):
    name: str
    default: float | list[float]
    minimum: float | list[float]
    maximum: float | list[float]
    description: str
    nonzero: bool = False
    presets: dict[str, list[float]] | None = None


class AugmentationInfo(BaseModel):
    name: str
    equation: str
    description: str
    parameters: list[ParameterInfo]


class RobotInfo(BaseModel):
    name: str
    title: str
    description: str
    equation: str
    p: int
    r: int
    variable_names: list[str]
    task_names: list[str]
    parameters: list[ParameterInfo]
    default_x0: list[float]
    default_target: list[float]
    default_path: list[list[float]]
    default_mode: Mode
    default_gamma: float
    x_range: list[list[float]]
    augmentations: list[AugmentationInfo]
    default_augmentation: str
    functional_region: dict[str, list[float]] = Field(
        description="the box of the paper's E1/E2 comparisons (sec. 5); empty if none"
    )
    algorithms: list[Algorithm]
    modes: list[Mode]


class Limits(BaseModel):
    max_cycles: int
    max_path_points: int
    max_iterations: int
    max_trajectory_points: int
    request_timeout_s: float


class AlgorithmInfo(BaseModel):
    """An inverse J# of eq. (7): its formula, source and parameters (``algorithm_parameters``)."""

    name: Algorithm
    equation: str
    source: str
    description: str
    parameters: list[ParameterInfo]
    vectors: list[str] = Field(description="its vector parameters: rest (p numbers), limits "
                               "(p pairs [lo, hi])")  # fmt: skip


class RobotsResponse(BaseModel):
    robots: list[RobotInfo]
    limits: Limits
    algorithms: list[AlgorithmInfo] = Field(
        default_factory=list, description="every algorithm and its parameters"
    )


SynthesisMethod = Literal["evaluate", "e2_variational"]
Bound = Annotated[float, Field(strict=True, ge=-100.0, le=100.0, allow_inf_nan=False)]


class SynthesizeRequest(BaseModel):
    """Synthesize or evaluate an augmenting map h over a box of the joint space."""

    model_config = ConfigDict(extra="forbid")

    robot: AnyRobot
    method: SynthesisMethod = Field(
        "evaluate",
        description="'evaluate': a catalogue map (analytic or already synthesized) on the box; "
        "'e2_variational': minimise E2 (eq. (19)) by the Ritz method (engine.variational)",
    )
    augmentation: AnyAugmentation | None = Field(
        None, description="for 'evaluate': the map and its parameters (default: the robot's)"
    )
    region: dict[str, tuple[Bound, Bound]] | None = Field(
        None,
        max_length=3,
        description="box {variable: [lo, hi]} (2 or 3 variables); default: the last 3 (2 for "
        "'e2_variational') variables, each over a tenth of its x_range either side of the "
        "robot's default start",
    )
    fixed: dict[str, FiniteFloat] | None = Field(
        None,
        max_length=MAX_DIMENSION,
        description="values of the variables not in the box (default: the default start)",
    )
    nodes: Annotated[int, Field(strict=True, ge=2, le=24), INTEGRAL] = Field(
        8, description="Gauss-Legendre nodes per variable for E1 and E2"
    )
    degree: Annotated[int, Field(strict=True, ge=1, le=24), INTEGRAL] = Field(
        10, description="'e2_variational': Legendre degree per variable"
    )
    grid: Annotated[int, Field(strict=True, ge=3, le=61), INTEGRAL] = Field(
        21, description="grid points per axis for h"
    )


def _synthesis_fields(spec: RobotSpec, augmentation: Any) -> dict[str, Any]:
    names = tuple(spec.variable_names)
    variable = Literal[names]  # type: ignore[valid-type]
    return {
        "augmentation": (
            augmentation | None,
            Field(
                None,
                description="for 'evaluate': the map and its parameters (one of "
                f"{sorted({a.name for a in spec.augmentations})}; default: "
                f"{spec.augmentation(None).name})",
            ),
        ),
        "region": (
            Annotated[dict[variable, tuple[Bound, Bound]], Field(min_length=1, max_length=3)]
            | None,
            Field(
                None,
                description=f"box {{variable: [lo, hi]}}, lo < hi, of 1 to 3 of "
                f"{list(names)} (2 or 3 draw a grid of h; 'e2_variational' needs 2 or 3), none "
                "of them fixed; default: the last 3 (2 for 'e2_variational') not fixed, each "
                "over a tenth of its range either side of the default start",
            ),
        ),
        "fixed": (
            dict[variable, FiniteFloat] | None,
            Field(
                None,
                description="values of the variables not in the box (default: the default start)",
            ),
        ),
    }


#: ``POST /synthesize``'s body: a :class:`SynthesizeRequest` with its robot's variables.
SynthesizeBody = per_robot(SynthesizeRequest, _synthesis_fields)


class FunctionalInfo(BaseModel):
    value: MaybeFloat
    n_points: int
    n_singular: int
    min_abs_dh_k: MaybeFloat


class SynthesisGrid(BaseModel):
    axes: dict[str, list[float]] = Field(description="the two grid variables and their values")
    h: list[list[MaybeFloat]] = Field(description="h[i][j] at (axis 1 [i], axis 2 [j])")


class SynthesizeResponse(BaseModel):
    robot: RobotUsed
    method: SynthesisMethod
    augmentation: AugmentationUsed
    region: dict[str, list[float]]
    fixed: dict[str, float]
    grid: SynthesisGrid | None
    coefficients: dict[str, float] = Field(
        description="polynomial coefficients, when there are any"
    )
    functionals: dict[str, FunctionalInfo | None] = Field(
        description="E1 (13) and E2 (18) of the map on the box; null where undefined (see message)"
    )
    convergence: list[dict[str, float]] = Field(
        description="'e2_variational': E2 against the Legendre degree"
    )
    message: str


class SynthesisMethodsResponse(BaseModel):
    methods: list[SynthesisMethod]
    notes: dict[str, str]


class ErrorResponse(BaseModel):
    """A request that could not be served now (503) or an unexpected failure (500)."""

    detail: str


#: OpenAPI entry of the 503 every computing endpoint may answer.
BUSY: dict[int | str, dict[str, Any]] = {
    503: {"model": ErrorResponse, "description": "server busy: no compute slot in time"}
}


class HealthResponse(BaseModel):
    status: Literal["ok"]


__all__ = [
    "AUGMENTATION_MODELS",
    "ROBOT_MODELS",
    "Augmentation",
    "ErrorResponse",
    "HealthResponse",
    "RepeatabilityRequest",
    "RepeatabilityResponse",
    "Robot",
    "RobotsResponse",
    "SolveRequest",
    "SolveResponse",
    "SynthesizeRequest",
    "SynthesizeResponse",
]
