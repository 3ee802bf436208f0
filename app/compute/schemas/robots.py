"""The robots and augmenting maps a request names, and how a response echoes them.

Catalogue models are generated from the engine's catalogue (:data:`jik.engine.registry.ROBOTS`)
when this module is imported: one model per robot with its parameters and their ranges,
discriminated by ``name``, and one per augmenting map. A robot or map the catalogue gains appears
in the API, its OpenAPI schema and the fuzz test with no change here. The robots a user defines
(planar chain, formulas, URDF) and their maps are written out below.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeAlias, Union

from pydantic import BaseModel, ConfigDict, Field, create_model

from ....engine import robot_synthesis as synthesis
from ....engine.arms import ARMS, Arm
from ....engine.formula import MAX_LENGTH as MAX_FORMULA_CHARS  # (the engine's bound)
from ....engine.registry import ROBOTS, AugmentationSpec, RobotSpec
from ....engine.robot_kinds import AUGMENTATIONS, COMMON, KINDS, MAX_TITLE_CHARS
from ....engine.urdf import MAX_URDF_BYTES
from .fields import (
    INTEGRAL,
    MAX_DIMENSION,
    Bound,
    Coordinate,
    FiniteFloat,
    FrameAxes,
    Vector,
    one_or_many,
)


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
                # (JSON Schema's way to say nonzero: the engine refuses 0 with a 422)
                json_schema_extra={"not": {"const": 0}} if p.nonzero else None,
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


# --------------------------------------------------------------------------------------------
# Robots defined by data: the kinds of jik.engine.robot_kinds, checked in full by
# jik.engine.robot_spec.robot_from_dict. The schema says what JSON Schema can (names, sizes,
# the joints' letters); the formulas' grammar, the URDF text and what follows from them (p, r,
# the lengths of x0, target and path) are checked when the robot is built, naming the field.

#: A variable's, a parameter's or a joint's name.
Name = Annotated[str, Field(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,31}$")]
FormulaText = Annotated[str, Field(min_length=1, max_length=MAX_FORMULA_CHARS)]
#: Named constants of a formula robot or map (lengths, offsets): numbers within +-1000, as
#: coordinates are (beyond that the kinematics only overflow).
Constants = Annotated[dict[Name, Coordinate], Field(max_length=32)]
#: A robot's title: its length bounded here, its one line (no control characters) checked by
#: the engine when the robot is built (robot_kinds.one_line).
Title = Annotated[str, Field(min_length=1, max_length=MAX_TITLE_CHARS)]


#: Optional joint limits of a planar chain or a formula robot (a URDF's come from its joints).
JointLimits = Annotated[
    list[tuple[FiniteFloat | None, FiniteFloat | None]],
    Field(min_length=1, max_length=MAX_DIMENSION),
]

#: An orientation R0: a rotation vector or a quaternion x y z w (numbers), or a 3x3 matrix.
Orientation = one_or_many(
    Annotated[list[FiniteFloat], Field(min_length=3, max_length=4)],
    Annotated[
        list[Annotated[list[FiniteFloat], Field(min_length=3, max_length=3)]],
        Field(min_length=3, max_length=3),
    ],
)


#: A URDF's joint or link name (any characters: URDF does not restrict them).
LinkName = Annotated[str, Field(min_length=1, max_length=200)]
#: Each kind's definition entries the API takes, as ``(type, default)`` (``...``: required;
#: ``dict``: an empty mapping): what JSON Schema can say of them. Their descriptions are the
#: engine's (:data:`jik.engine.robot_kinds.KINDS`, ``AUGMENTATIONS``), the one text the
#: dashboard's robot editor shows too; a robot file's ``urdf_file`` and a map's ``label`` are
#: not a request's.
_ENTRIES: dict[str, dict[str, tuple[Any, Any]]] = {
    "planar_chain": {
        "joints": (Annotated[str, Field(pattern=rf"^[RPrp]{{1,{MAX_DIMENSION}}}$")], ...),
        "lengths": (Vector, ...),
        "offsets": (Vector | None, None),
        "orientation": (Annotated[bool, Field(strict=True)], False),
        "limits": (JointLimits | None, None),
    },
    "formula": {
        "variables": (Annotated[list[Name], Field(min_length=1, max_length=MAX_DIMENSION)], ...),
        "task": (Annotated[list[FormulaText], Field(min_length=1, max_length=MAX_DIMENSION)], ...),
        "parameters": (Constants, dict),
        "limits": (JointLimits | None, None),
    },
    "urdf": {
        "urdf": (Annotated[str, Field(min_length=1, max_length=MAX_URDF_BYTES)], ...),
        "end_link": (LinkName, ...),
        "base_link": (LinkName | None, None),
        "active_joints": (
            Annotated[list[LinkName], Field(min_length=1, max_length=MAX_DIMENSION)] | None,
            None,
        ),
        "task": (
            Annotated[str, Field(min_length=1, max_length=40, pattern=r"^[xyzrpose ,]+$")],
            "xyz",
        ),
        "home": (Vector | None, None),
        "reference": (Orientation | None, None),
        "locked": (Annotated[dict[LinkName, FiniteFloat], Field(max_length=64)], dict),
    },
    "formula map": {
        "h": (FormulaText | Annotated[list[FormulaText], Field(min_length=1, max_length=15)], ...),
        "parameters": (Constants | None, None),
    },
    "e2_synthesized": {
        "region": (
            Annotated[
                dict[Name, tuple[Bound, Bound]], Field(min_length=2, max_length=MAX_DIMENSION)
            ]
            | None,
            None,
        ),
        "degree": (
            Annotated[int, Field(strict=True, ge=1, le=synthesis.MAX_TENSOR_DEGREE), INTEGRAL]
            | None,
            None,
        ),
        "fixed": (Annotated[dict[Name, FiniteFloat], Field(max_length=MAX_DIMENSION)] | None, None),
        "frame_axes": (FrameAxes | None, None),
    },
}


def _definition_model(cls: str, entries: str, title: str, doc: str) -> type[BaseModel]:
    """The request model ``cls`` of a definition: its ``name``, the entries of
    :data:`_ENTRIES` ``[entries]`` described by the engine, and a robot's ``title``."""
    robot = entries in KINDS
    kind = entries.replace("formula map", "formula")
    said = {f.name: f.help for f in (*(KINDS[kind] if robot else AUGMENTATIONS[kind]), *COMMON)}
    fields: dict[str, Any] = {"name": (Literal[kind], ...)}
    for key, (kind_of, default) in _ENTRIES[entries].items():
        made = {"default_factory": dict} if default is dict else {"default": default}
        made = Field(**made, description=said[key])
        fields[key] = (kind_of, made)
    if robot:
        fields["title"] = (Title | None, Field(None, description=said["title"]))
    return create_model(
        cls, __config__=ConfigDict(extra="forbid", title=title), __doc__=doc, **fields
    )


PlanarChainRobot = _definition_model(
    "PlanarChainRobot",
    "planar_chain",
    "Planar chain",
    "A planar serial chain of revolute (R) and prismatic (P) joints: the end point (r = 2), or "
    "the end point and its angle (r = 3); p is the number of joints.",
)
FormulaRobot = _definition_model(
    "FormulaRobot",
    "formula",
    "Formula robot",
    "Kinematics written as formulas: k(x) = (task[0], task[1], ...) in the variables.",
)
UrdfRobot = _definition_model(
    "UrdfRobot",
    "urdf",
    "URDF arm",
    "A serial arm from URDF text: the end link's pose (task 'pose', 'xyz' or a subset).",
)
FormulaMapAugmentation = _definition_model(
    "FormulaMapAugmentation",
    "formula map",
    "Formula map",
    "An augmenting map h written as a formula in the robot's variables, eq. (9); for p - r > 1 "
    "a list of p - r formulas (the extended inverse of several maps).",
)
E2SynthesisAugmentation = _definition_model(
    "E2SynthesisAugmentation",
    "e2_synthesized",
    "E2-synthesized map",
    "The E2-optimal map on a box: for p = r + 1, the Ritz solve of eq. (20) on a tensor Legendre "
    "basis for two or three variables, on a total-degree basis with a Sobol rule for more; for "
    "p - r > 1, the maps h_1..h_(p-r) on the total-degree basis (docs/e2-vector.md).",
)


def _arm_model(arm: Arm) -> type[BaseModel]:
    """A catalogue arm's request model: the URDF robot's fields that choose its task."""
    fields: dict[str, Any] = {"name": (Literal[arm.name], ...)}
    for key in ("task", "reference", "home", "title"):
        info = UrdfRobot.model_fields[key]
        text = info.description or ""
        if key == "task":  # (a URDF's default task is xyz; the arm's is its own)
            text = text.replace("(default xyz)", f"(default {arm.task})")
        fields[key] = (
            info.annotation,
            Field(arm.task if key == "task" else None, description=text),
        )
    return create_model(
        f"{_camel(arm.name)}Arm",
        __config__=ConfigDict(extra="forbid", title=arm.title),
        __doc__=f"{arm.title} from jik's catalogue: {arm.description}. Default task "
        f"{arm.task!r}; R0 defaults to the orientation at home {list(arm.home)}.",
        **fields,
    )


#: The robots a user defines, by kind (their ``name``); a catalogue arm is one too.
USER_ROBOT_MODELS: dict[str, type[BaseModel]] = {
    "planar_chain": PlanarChainRobot,
    "formula": FormulaRobot,
    "urdf": UrdfRobot,
    **{name: _arm_model(arm) for name, arm in ARMS.items()},
}
for _m in (*ROBOT_MODELS.values(), *AUGMENTATION_MODELS.values(), *USER_ROBOT_MODELS.values()):
    globals()[_m.__name__] = _m  # importable by name (pickling, introspection)
#: The augmenting maps a user robot takes, by name.
USER_AUGMENTATION_MODELS: dict[str, type[BaseModel]] = {
    "formula": FormulaMapAugmentation,
    "e2_synthesized": E2SynthesisAugmentation,
}
#: Every robot name a request may give: the catalogue's, then the kinds of user robots.
ROBOT_NAMES = [*ROBOTS, *USER_ROBOT_MODELS]

if TYPE_CHECKING:
    # Generated from the catalogue and robot_kinds at import time (above), so their fields are
    # invisible to a static checker: type them as Any there.
    AnyRobot: TypeAlias = Any
    AnyAugmentation: TypeAlias = Any
    UserAugmentation: TypeAlias = Any
else:
    #: Any robot and map of a request: the base request models, which the workers validate
    #: with, take them all; the routes take the exact per-robot members of :func:`per_robot`.
    AnyRobot = _union([*ROBOT_MODELS.values(), *USER_ROBOT_MODELS.values()])
    UserAugmentation = _union(list(USER_AUGMENTATION_MODELS.values()))
    AnyAugmentation = _union(list(AUGMENTATION_MODELS.values())) | UserAugmentation


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


class UnitsInfo(BaseModel):
    """The units of the response's configurations x and task points y (k(x), targets):
    :meth:`jik.engine.units.RobotUnits.summary`."""

    x: list[str] = Field(
        description="each joint variable's unit, in x's order: rad, m, 1 (dimensionless), "
        "m/s, rad/s; '' where the robot states none (a formula robot)"
    )
    y: list[str] = Field(description="each task coordinate's unit, in k(x)'s order")
    lengths: str = Field(description="what the robot's length unit m stands for")


class RobotUsed(BaseModel):
    """The robot a run used, with every parameter (defaults filled in)."""

    name: str
    title: str = Field(description="the robot's name for a reader (Manipulator 2, Franka Panda)")
    parameters: dict[str, float | list[float]]
    definition: dict[str, Any] | None = Field(
        default=None,
        exclude_if=_absent,
        description="a user robot's definition as given, a URDF's text replaced by its size and "
        "SHA-256 (absent for a catalogue robot)",
    )
    p: int | None = Field(default=None, exclude_if=_absent, description="a user robot's p")
    r: int | None = Field(default=None, exclude_if=_absent, description="a user robot's r")
    notes: list[str] | None = Field(
        default=None,
        exclude_if=_absent,
        description="what was skipped while building the robot (a URDF's mesh references)",
    )
    units: UnitsInfo = Field(description="the units of x and y")
