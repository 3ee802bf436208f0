"""The parameters of the inverses J# (damped, weighted, posture), built from the engine's
catalogue :data:`jik.engine.registry.ALGORITHMS`, so their ranges are written once."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, create_model

from ....engine.exports import json_values
from ....engine.registry import ALGORITHMS
from .fields import Coordinate

#: Every algorithm of the engine, as the API names them.
Algorithm = Literal["pseudoinverse", "extended", "damped", "weighted", "posture"]
assert set(Algorithm.__args__) == set(ALGORITHMS)  # type: ignore[attr-defined]

_Bound = Annotated[float, Field(strict=True, allow_inf_nan=True)]


def _scalar_fields() -> dict[str, Any]:
    fields: dict[str, Any] = {}
    for spec in ALGORITHMS.values():
        for p in spec.parameters:
            kind = Annotated[
                float, Field(strict=True, ge=p.minimum, le=p.maximum, allow_inf_nan=False)
            ]
            fields[p.name] = (
                kind | None,
                Field(None, description=f"{spec.name}: {p.description} (default {p.default:g})"),
            )
    return fields


_Parameters = create_model("_Parameters", __config__=ConfigDict(extra="forbid"), **_scalar_fields())


class AlgorithmParameters(_Parameters):  # type: ignore[misc, valid-type]
    """Parameters of the chosen algorithm; those of another algorithm are refused (422)."""

    rest: list[Coordinate] | None = Field(
        None,
        description="posture: the rest posture x_rest, length p, within the robot's joint "
        "limits if it has some (default: the robot's home, else the run's x0; in an atlas, "
        "each run's own start)",
    )
    limits: list[tuple[_Bound, _Bound]] | None = Field(
        None,
        description="weighted: joint limits [lo, hi] per joint, length p (default: the "
        "robot's joint limits, a side without one taking its configuration box x_range's; no "
        "limits: the box x_range)",
    )


def used(params: BaseModel | None) -> dict:
    """The parameters given, as the engine's :func:`make_inverse` takes them (the posture
    inverse's ``rest``, when not given, is the engine's
    :func:`~jik.engine.algorithm_registry.default_rest` at the run's start)."""
    return {} if params is None else params.model_dump(exclude_none=True)


def parameters_of(inverse) -> dict[str, Any]:
    """The parameters an engine inverse holds (its ``parameters``), by the catalogue's names,
    defaults filled in (posture's rest, weighted's limits, with None for an unbounded end): what
    a response says the run used."""
    values = inverse.parameters
    names = ALGORITHMS[inverse.name].names
    return {name: json_values(np.asarray(values[name], dtype=float)) for name in names}


def field_of(exc_field: str | None) -> str:
    """The request's field for the field of an engine error about an algorithm's parameter
    (:attr:`InvalidInputError.field <jik.engine.exceptions.InvalidInputError>`: ``gamma``,
    ``rest.3``); the start ``x0``, which the posture inverse's default rest is, keeps its own
    name."""
    if exc_field is None:
        return "algorithm_parameters"
    if exc_field.split(".")[0] == "x0":
        return exc_field
    return f"algorithm_parameters.{exc_field}"
