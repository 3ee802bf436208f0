"""The catalogue's description (``GET /robots``), health and the error body."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, Field

from ....engine.solve_rules import Mode
from .algorithms import Algorithm


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


class CoordinateInfo(BaseModel):
    """A joint variable or task coordinate and its unit (:mod:`jik.engine.units`)."""

    name: str
    unit: str = Field(
        description="rad, m, 1 (dimensionless), m/s, rad/s; '' where the robot states none "
        "(a formula robot)"
    )
    joint: str | None = Field(None, description="a URDF arm's joint of this variable")
    limits: list[float | None] | None = Field(
        None, description="the joint's [lower, upper] (null: no bound on that side)"
    )
    home: float | None = Field(None, description="its value at the arm's home")


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
    default_path_loops: bool = Field(
        description="whether default_path is a closed task path that /repeatability and "
        "/atlas drive by default (false: an experiment's targets, the unicycle's, reached once)"
    )
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
    variables: list[CoordinateInfo] = Field(
        description="the p joint variables, in x's order: units, a URDF arm's joint names, the "
        "joint limits and home where the robot has them"
    )
    task: list[CoordinateInfo] = Field(description="the r task coordinates, in k's order")
    lengths: str = Field(description="what the robot's length unit m stands for")


class Limits(BaseModel):
    """The bounds of ``/solve`` and ``/repeatability`` requests (an atlas's own, smaller, are
    in ``AtlasRequest``'s schema)."""

    max_cycles: int = Field(description="most cycles of a /repeatability run")
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
    vectors: list[str] = Field(
        description="its vector parameters: rest (p numbers), limits (p pairs [lo, hi])"
    )


class RobotsResponse(BaseModel):
    robots: list[RobotInfo]
    limits: Limits
    algorithms: list[AlgorithmInfo] = Field(
        default_factory=list, description="every algorithm and its parameters"
    )


class ErrorResponse(BaseModel):
    """An error in words: every status but 422 and 415, whose detail lists the fields."""

    detail: str


#: OpenAPI entry of the 503 every computing endpoint may answer.
BUSY: dict[int | str, dict[str, Any]] = {
    503: {"model": ErrorResponse, "description": "server busy: no compute slot in time"}
}


class HealthResponse(BaseModel):
    status: Literal["ok"]
