"""One request model per robot: what a route takes and its OpenAPI document shows."""

from __future__ import annotations

from typing import Annotated, Any, Union

from pydantic import BaseModel, BeforeValidator, Discriminator, Field, Tag, create_model
from pydantic_core import PydanticCustomError

from ....engine.registry import ROBOTS
from .examples import schema_examples
from .robots import (
    AUGMENTATION_MODELS,
    ROBOT_MODELS,
    ROBOT_NAMES,
    USER_ROBOT_MODELS,
    UserAugmentation,
    _camel,
    _union,
)


def _robot_name(body: Any) -> str | None:
    """The robot's name in a request body (raw JSON data or a model): the variant to check."""
    robot = body.get("robot") if isinstance(body, dict) else getattr(body, "robot", None)
    name = robot.get("name") if isinstance(robot, dict) else getattr(robot, "name", None)
    return name if isinstance(name, str) else None


def _object(body: Any) -> Any:
    """A body that is a JSON object (or a model), else the error that says so: an array or a
    scalar has no robot to choose the variant by."""
    if not isinstance(body, dict | BaseModel):
        raise PydanticCustomError("model_type", "the body must be a JSON object")
    return body


def narrowed(base: type[BaseModel], name: str, annotation: Any) -> tuple[Any, Any]:
    """The field ``name`` of ``base`` with another type (a robot's lengths, its maps), its
    default and description kept, its constraints the new type's: a field of
    :func:`per_robot`'s ``fields``."""
    info = base.model_fields[name]
    return annotation, Field(info.default, description=info.description)


def per_robot(base: type[BaseModel], fields: Any, user_fields: Any = None) -> Any:
    """``base`` made exact for each robot of the catalogue: one model per robot, chosen by
    ``robot.name``, whose ``robot`` and ``augmentation`` (if ``base`` has one: the robot's maps,
    named with its default) are that robot's and whose vectors have its lengths
    (``fields(spec)``: the other fields that differ from ``base``'s), and one per kind of user
    robot (``user_fields(kind)``; default: its maps, :func:`user_maps`). Their union is what the
    route takes and what its OpenAPI document shows, each member with its robot's example
    (:mod:`.examples`); each member is still a ``base``. A body must be a JSON object, and an
    unknown name is refused naming every robot a request may give."""
    route = base.__name__.removesuffix("Request")

    def member(name: str, robot: Any, title: Any, about: Any, more: dict[str, Any]) -> Any:
        model = create_model(
            f"{route}{_camel(name)}Request",
            __base__=base,
            __doc__=f"{(base.__doc__ or '').strip()} ({title})",
            __cls_kwargs__={"json_schema_extra": schema_examples(route.lower(), name)},
            robot=(robot, Field(description=about)),
            **more,
        )
        globals()[model.__name__] = model  # importable by name (pickling, introspection)
        return Annotated[model, Tag(name)]

    members = []
    for name, spec in ROBOTS.items():
        more = fields(spec)
        if "augmentation" in base.model_fields:
            names = list(dict.fromkeys(a.name for a in spec.augmentations))
            maps = _union([AUGMENTATION_MODELS[a] for a in names])
            info = base.model_fields["augmentation"]
            default = spec.augmentation(None).name
            said = f"{info.description}; {spec.title}'s: one of {sorted(names)}, default {default}"
            more["augmentation"] = (maps | None, Field(None, description=said))
        about = f"{spec.title} and its parameters"
        members.append(member(name, ROBOT_MODELS[name], spec.title, about, more))
    for kind, model in USER_ROBOT_MODELS.items():
        # p and r follow from the definition: the vectors keep the base's 1 to 16 components,
        # checked against the built robot (a 422 naming the field and the robot's p, r).
        more = (user_fields or (lambda kind: user_maps(base)))(kind)
        members.append(member(kind, model, model.model_config.get("title"), model.__doc__, more))
    return Annotated[
        Union[tuple(members)],  # noqa: UP007
        Discriminator(
            _robot_name,
            custom_error_type="unknown_robot",
            custom_error_message=f"give a robot whose name is one of {ROBOT_NAMES}",
        ),
        BeforeValidator(_object),
    ]


def user_maps(base: type[BaseModel]) -> dict[str, Any]:
    """The ``augmentation`` field of ``base`` made for a user robot: a map it defines."""
    return {
        "augmentation": (
            UserAugmentation | None,
            Field(
                None,
                description="augmenting map h of the extended inverse: "
                "{'name': 'formula', 'h': ...} or {'name': 'e2_synthesized', 'region': "
                "{...}} (p = r + 1)" + USER_AUGMENTATION_NOTE.get(base.__name__, ""),
            ),
        )
    }


#: What the augmentation of a user robot's request is for, by request.
USER_AUGMENTATION_NOTE = {
    "SynthesizeRequest": "; 'evaluate' needs one, 'e2_variational' and 'e2_total_degree' take none",
    "AtlasRequest": "; default: the robot's (a catalogue arm with one degree of redundancy: "
    "E2-optimal over all its joints)",
}
