"""Request and response models of the atlas jobs (``POST /atlas``, ``GET /atlas/{id}``); what
needs the registry or the engine (vector lengths, a path the curve tracing refuses, the size of
the work) is checked by :func:`jik.app.compute.atlas_plan.planned`, which names the field.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, Field

from ...engine.repeatability import MAX_PATH_POINTS
from .schemas import (
    INTEGRAL,
    Algorithm,
    AnyAugmentation,
    AugmentationUsed,
    Coordinate,
    MaybeFloat,
    RobotUsed,
    Vector,
    per_robot,
)
from .schemas.algorithms import AlgorithmParameters
from .schemas.fields import Seed, coordinates, points
from .schemas.runs import RunSettings
from .schemas.variants import narrowed

#: Largest starts per path, cycles, and paths of a family (shifts, scales) in one request.
MAX_STARTS = 20000
MAX_CYCLES = 50
MAX_FAMILY = 16
#: Largest number of explicit starts (their coordinates travel in the request).
MAX_START_POINTS = 4096

Scale = Annotated[float, Field(strict=True, gt=0, le=100.0, allow_inf_nan=False)]
StartPoints = Annotated[list[Vector], Field(min_length=1, max_length=MAX_START_POINTS)]


class AtlasRequest(RunSettings):
    """A repeatability atlas: the drift after each cycle of a closed path, for many starts on the
    self-motion curve of the path's first point (engine.atlas)."""

    algorithms: Annotated[list[Algorithm], Field(min_length=1, max_length=5)] = Field(
        ["pseudoinverse"],
        description="the algorithms to compare over the same starts, each once: 'pseudoinverse' "
        "(8), 'extended' (11), 'damped', 'weighted', 'posture'",
    )
    algorithm_parameters: AlgorithmParameters | None = Field(
        None,
        description="parameters of the damped, weighted and posture algorithms (each "
        "takes its own; default: the engine's; without rest the posture inverse pulls each "
        "run toward its own start)",
    )
    augmentation: AnyAugmentation | None = Field(
        None, description="augmenting map of the extended inverse (default: the robot's)"
    )
    path: Annotated[list[Vector], Field(min_length=2, max_length=MAX_PATH_POINTS)] | None = Field(
        None,
        description="task points, a loop from the first: the starts lie on k(x) = path[0] "
        "(default: the robot's closed path)",
    )
    starts: Annotated[int, Field(strict=True, ge=1, le=MAX_STARTS), INTEGRAL] = Field(
        256, description=f"starts per path, 1 to {MAX_STARTS}"
    )
    start_points: StartPoints | None = Field(
        None,
        description="explicit starts (N, p), each on k(x) = path[0] (to 1e-9): a robot "
        "with p - r > 1, whose self-motion manifolds are not curves, needs them; starts, "
        "sampling, seed, arc and reference are then not used",
    )
    sampling: Literal["grid", "sample"] = Field(
        "grid", description="arc lengths on a grid (ends included) or sampled uniformly"
    )
    seed: Seed = 0
    arc: tuple[Coordinate, Coordinate] | None = Field(
        None,
        description="(lo, hi), lo <= 0 <= hi: arc lengths of the starts; default: the part "
        "of the curve inside the robot's configuration box",
    )
    reference: Vector | None = Field(
        None,
        description="s = 0 is where eq. (7) from here meets the curve (default: the robot's x0)",
    )
    shifts: Annotated[list[Vector], Field(min_length=1, max_length=MAX_FAMILY)] | None = Field(
        None, description="translations of the path (a family of paths)"
    )
    scales: Annotated[list[Scale], Field(min_length=1, max_length=MAX_FAMILY)] | None = Field(
        None, description="scales of the path about its first point"
    )
    cycles: Annotated[int, Field(strict=True, ge=1, le=MAX_CYCLES), INTEGRAL] = 3
    leg_ends: bool = Field(False, strict=True, description="include every leg's end in the result")


def _atlas_fields(spec) -> dict:
    return {
        "path": (
            points(spec.r, 2, MAX_PATH_POINTS) | None,
            Field(
                None,
                description=f"task points {list(spec.task_names)}, a loop from the "
                "first: the starts lie on k(x) = path[0] (default: the robot's closed "
                "path)",
            ),
        ),
        "reference": narrowed(AtlasRequest, "reference", coordinates(spec.p) | None),
        "shifts": narrowed(AtlasRequest, "shifts", points(spec.r, 1, MAX_FAMILY) | None),
    }


#: ``POST /atlas``'s body: an :class:`AtlasRequest` with its robot's lengths and maps (a
#: robot defined in the request, or a catalogue arm, keeps the base's vectors, checked against
#: the built robot).
AtlasBody = per_robot(AtlasRequest, _atlas_fields)


class AtlasResult(BaseModel):
    """The atlas, per algorithm: axes (path, start, cycle), runs = paths x starts."""

    algorithms: list[Algorithm]
    arc: list[float] = Field(description="the arc lengths the starts span (none: explicit starts)")
    paths: list[list[list[float]]] = Field(description="(P, L, r): the family's paths")
    parameter: list[float] = Field(description="(N,): arc length s of each start")
    period: float | None = Field(
        None,
        description="the length of one turn of the starts' self-motion curve when it closes on "
        "itself (the arc is then one turn and the starts cover it once); null for an open curve "
        "or explicit starts",
    )
    starts: list[list[list[float]]] = Field(description="(P, N, p)")
    drift: dict[str, list[list[list[MaybeFloat]]]] = Field(
        description="per algorithm (P, N, cycles): ||x after cycle c - x0||; null after a failure"
    )
    success: dict[str, list[list[bool]]]
    failures: dict[str, dict[str, str]] = Field(
        description="per algorithm, 'path,start' -> why that run failed"
    )
    leg_ends: dict[str, list[list[list[list[MaybeFloat]]]]] | None = Field(
        None, description="per algorithm (P, N, cycles * L, p), when asked for"
    )
    outside_limits: dict[str, int] | None = Field(
        None,
        description="per algorithm, the runs whose start or some leg end is outside the "
        "robot's joint limits; null for a robot without limits",
    )


#: An atlas job's state.
Status = Literal["queued", "running", "done", "failed", "cancelled"]


class AtlasJobResponse(BaseModel):
    """An atlas job: its state, progress and, once done, its result."""

    id: str
    status: Status
    runs: int = Field(description="runs per algorithm: paths x starts")
    runs_done: int
    progress: float = Field(description="runs_done / runs")
    elapsed_s: float
    queue_position: int | None = Field(
        None,
        description="while queued: how many atlas jobs run or wait before it (the server "
        "computes a few at once, in the order they were started); null once it runs",
    )
    message: str = Field("", description="the state in words, e.g. what a queued job waits for")
    robot: RobotUsed | None = Field(
        None, description="the robot used, as every run's response names it (its notes too)"
    )
    augmentation: AugmentationUsed | None = Field(
        None, description="the map the extended inverse used; null without it"
    )
    error: str | None = None
    result: AtlasResult | None = None
