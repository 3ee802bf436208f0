"""``POST /synthesize`` and ``GET /synthesize``: synthesis of augmenting maps on a box."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from jik.app.compute.schemas.fields import (
    INTEGRAL,
    MAX_DIMENSION,
    Bound,
    FiniteFloat,
    MaybeFloat,
)
from jik.app.compute.schemas.robots import AnyAugmentation, AnyRobot, AugmentationUsed, RobotUsed
from jik.app.compute.schemas.variants import per_robot
from jik.engine.registry import RobotSpec

SynthesisMethod = Literal["evaluate", "e2_variational"]


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
