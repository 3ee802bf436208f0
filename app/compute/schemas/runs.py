"""``POST /solve`` and ``POST /repeatability``: their requests, bodies and responses.

What needs the registry (vector lengths against p and r, an augmentation that belongs to the
robot, a singular start) is checked by :mod:`jik.app.compute.requests`, which names the field.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from ....engine.registry import RobotSpec
from ....engine.repeatability import MAX_CYCLES, MAX_PATH_POINTS, REPEATABLE_DRIFT
from ....engine.solve_rules import DISCRETE_GAMMA_BOUND, Mode, Status
from .algorithms import Algorithm, AlgorithmParameters
from .fields import (
    INTEGRAL,
    Gamma,
    IterationCap,
    MaybeFloat,
    Tolerance,
    Vector,
    coordinates,
    points,
)
from .robots import (
    AnyAugmentation,
    AnyRobot,
    AugmentationUsed,
    RobotUsed,
    _absent,
)
from .variants import per_robot

#: What a run takes when its request gives no start, target or path.
DEFAULT_X0 = "default: the robot's start (GET /robots: default_x0)"
DEFAULT_TARGET = "default: the robot's target (GET /robots: default_target)"
DEFAULT_PATH = (
    "default: the robot's closed path (GET /robots: default_path, where default_path_loops)"
)


class RunSettings(BaseModel):
    """What every run of a request shares (a solve's, a repeatability's, an atlas's legs)."""

    model_config = ConfigDict(extra="forbid")

    robot: AnyRobot = Field(
        description="the robot and its parameters, e.g. {'name': 'manipulator2'}, a catalogue "
        "arm {'name': 'panda', 'task': 'pose'} or a robot defined in the request (planar_chain, "
        "formula, urdf)"
    )
    gamma: Gamma | None = Field(
        None,
        description=f"decay rate > 0 of eq. (5) (discrete: the step, < {DISCRETE_GAMMA_BOUND:g}); "
        "default: the robot's",
    )
    mode: Mode | None = Field(
        None, description="'continuous' (ODE) or 'discrete' (iterations); default: the robot's"
    )
    tolerance: Tolerance = Field(1e-10, description="stop when ||k(x) - target|| < tolerance")
    max_iterations: IterationCap | None = Field(
        None,
        description="cap on integrator steps (continuous) or iterations (discrete) per solve "
        "(per leg of a path); default: the engine's for the mode",
    )


class _Request(RunSettings):
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
        "default: the robot's default augmentation (the other algorithms take none)",
    )
    x0: Vector | None = Field(
        None, description=f"start configuration, length p of the robot; {DEFAULT_X0}"
    )


class SolveRequest(_Request):
    """One run of the continuation algorithm (7) from x0 to a target task point."""

    target: Vector | None = Field(
        None, description=f"target task point, length r of the robot; {DEFAULT_TARGET}"
    )


class RepeatabilityRequest(_Request):
    """Drive the robot ``cycles`` times around a closed task-space path (Table 1)."""

    path: Annotated[list[Vector], Field(min_length=1, max_length=MAX_PATH_POINTS)] | None = Field(
        None,
        description=f"task points visited in order, 1 to {MAX_PATH_POINTS}; k(x0) closes it; "
        f"{DEFAULT_PATH}",
    )
    cycles: Annotated[int, Field(strict=True, ge=1, le=MAX_CYCLES), INTEGRAL] = Field(
        1, description=f"1 to {MAX_CYCLES}"
    )


class Trajectory(BaseModel):
    """The run point by point (accepted integrator steps or iterations)."""

    theta: list[MaybeFloat] = Field(description="continuation parameter, or iteration number")
    x: list[list[MaybeFloat]] = Field(description="configurations, shape (m, p)")
    y: list[list[MaybeFloat]] = Field(description="k(x), shape (m, r)")
    error: list[MaybeFloat] = Field(description="||k(x) - target||, shape (m,)")
    h: list[MaybeFloat] | list[list[MaybeFloat]] | None = Field(
        None,
        description="h(x) for the extended inverse: shape (m,), or (m, p - r) for a map of "
        "p - r > 1 components",
    )
    points: int = Field(description="points of the full trajectory before downsampling")
    downsampled: bool


class LimitViolationInfo(BaseModel):
    """Where a run first left the joint limits (cycle 0, leg 0: the start x0)."""

    cycle: int = Field(description="from 1; 0 for the start x0")
    leg: int = Field(description="from 1 within its cycle; 0 for the start x0")
    joint: int = Field(description="index in x, from 0")
    name: str = Field(description="the variable's name (and the URDF joint's)")
    value: float = Field(description="the joint's value there (in its unit, robot.units.x)")
    limit: float = Field(description="the bound it passed")
    bound: Literal["lower", "upper"]


class LimitsInfo(BaseModel):
    """Whether the run stayed within the robot's joint limits (its whole trajectory)."""

    within: bool
    violation: LimitViolationInfo | None = Field(description="the first violation, if any")
    farthest: LimitViolationInfo | None = Field(
        description="the farthest excursion beyond a limit (the joint and where), if any"
    )
    ends_outside: bool = Field(description="whether the run's last configuration is outside")


class _RunResponse(BaseModel):
    robot: RobotUsed
    algorithm: Algorithm
    algorithm_parameters: dict[str, float | list[float | None] | list[list[float | None]]] = Field(
        default_factory=dict,
        description="the parameters the inverse used, defaults filled in (damped: damping, "
        "damping_threshold; weighted: limits, null for an unbounded end; posture: gain, rest)",
    )
    augmentation: AugmentationUsed | None
    mode: Mode
    gamma: float


#: A run's joint-limit report, the last field of its response.
RunLimits = Annotated[
    LimitsInfo | None,
    Field(
        exclude_if=_absent,
        description="whether the run stayed within the joint limits (absent: none)",
    ),
]


#: Why a solve stopped: the engine's SolveResult.status of one run.
RunStatus = Literal["converged", "max_steps", "diverged", "stalled", "singular", "undefined"]
assert set(RunStatus.__args__) == set(Status.NAMES) - {"running"}  # type: ignore[attr-defined]


class SolveResponse(_RunResponse):
    tolerance: float
    x0: list[float] = Field(description="the start configuration (the robot's, if not given)")
    target: list[float] = Field(description="the target task point (the robot's, if not given)")
    x: list[MaybeFloat] = Field(
        description="final configuration (null entries if the run diverged)"
    )
    y: list[MaybeFloat] = Field(description="k(x)")
    error: MaybeFloat = Field(description="||k(x) - target||")
    converged: bool
    message: str
    status: RunStatus = Field(
        description="why the run stopped: converged, max_steps (out of iterations or "
        "integrator steps), diverged, stalled, singular (the inverse singular there) or "
        "undefined (the augmenting map h undefined there)"
    )
    iterations: int = Field(description="integrator steps or iterations taken")
    trajectory: Trajectory
    limits: RunLimits = None


class Sentence(BaseModel):
    """One sentence of what a run found (:meth:`jik.engine.RepeatabilityResult.findings`)."""

    text: str
    role: Literal["finding", "why", "note", "failure"] = Field(
        description="finding: what the run did; why; note; failure: where it stopped"
    )


class RepeatabilityResponse(_RunResponse):
    cycles: int
    x0: list[float] = Field(description="the start configuration (the robot's, if not given)")
    targets: list[list[float]] = Field(description="task point of each leg of one cycle (closed)")
    legs: list[list[MaybeFloat]] = Field(
        description="configuration after each leg, all cycles (null after a failed leg)"
    )
    cycle_end: list[list[MaybeFloat]] = Field(description="configuration at the end of each cycle")
    drift: list[MaybeFloat] = Field(description="||cycle_end[c] - x0|| per cycle")
    max_drift: MaybeFloat
    repeatable: bool = Field(
        description=f"every leg succeeded and max drift < {REPEATABLE_DRIFT:g}"
    )
    success: bool
    message: str
    stopped_at: list[MaybeFloat] | None = Field(
        None,
        description="where a failed leg stopped, the configuration it reached (its legs entry "
        "is null); null for a run that completed",
    )
    findings: list[Sentence] = Field(
        description="what the run found and why, the dashboard's sentences: repeatable or not; "
        "for J^E# (11) whether h stayed at h(x0), eq. (12); in discrete mode what gamma did; "
        "for the damped, weighted and posture inverses what their parameters did"
    )
    limits: RunLimits = None


def _run_fields(spec: RobotSpec) -> dict[str, Any]:
    return {
        "x0": (
            coordinates(spec.p) | None,
            Field(
                None, description=f"start configuration {list(spec.variable_names)}; {DEFAULT_X0}"
            ),
        ),
    }


#: ``POST /solve``'s body: a :class:`SolveRequest` with the lengths of its robot.
SolveBody = per_robot(
    SolveRequest,
    lambda spec: {
        **_run_fields(spec),
        "target": (
            coordinates(spec.r) | None,
            Field(None, description=f"target {list(spec.task_names)}; {DEFAULT_TARGET}"),
        ),
    },
)
#: ``POST /repeatability``'s body: a :class:`RepeatabilityRequest` with its robot's lengths.
RepeatabilityBody = per_robot(
    RepeatabilityRequest,
    lambda spec: {
        **_run_fields(spec),
        "path": (
            points(spec.r, 1, MAX_PATH_POINTS) | None,
            Field(
                None,
                description=f"task points {list(spec.task_names)} visited in order, 1 to "
                f"{MAX_PATH_POINTS}; k(x0) closes it; {DEFAULT_PATH}",
            ),
        ),
    },
)
