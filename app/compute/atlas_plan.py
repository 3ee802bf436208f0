"""The plan of a REST atlas and its result document: a request's robot, inverses and paths
checked and traced into an :class:`~jik.engine.atlas.AtlasPlan` (:func:`planned`, run in a
compute worker by :func:`plan_task`: tracing the self-motion curves solves eq. (7)), the limits
of the atlas jobs (:class:`AtlasLimits`), and the fields of a finished atlas
(:func:`result_document`). The jobs that run the plans are :mod:`jik.app.compute.atlas_jobs`'.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...engine.atlas import AtlasPlan, plan_atlas
from ...engine.atlas_run import sized_chunks
from ...engine.atlas_table import AtlasResult
from ...engine.exceptions import InvalidInputError
from ...engine.repeatability import open_loop
from ...engine.self_motion import MAX_ARC
from . import schemas as S
from .atlas_schemas import AtlasRequest
from .documents import nullable
from .exceptions import RequestError
from .robot_requests import check_length, gamma_and_mode, request_robot
from .schemas.wording import without_field
from .worker import task

#: Seconds of work in one chunk of a server's atlas (:func:`jik.engine.atlas_run.sized_chunks`):
#: the compute workers serve the API's requests between chunks, first come first served, and a
#: chunk stays far within their time limit.
CHUNK_SECONDS = 1.0
#: What an atlas job's response repeats of its request: the robot used, the map used.
Used = tuple[S.RobotUsed, S.AugmentationUsed | None]


@dataclass(frozen=True)
class AtlasLimits:
    max_jobs: int = 16
    max_running: int = 1
    #: queued or running jobs of one REST client (an address), or of one dashboard session
    per_client: int = 2
    #: queued or running jobs of one address, its REST requests and its sessions together
    per_address: int = 8
    #: legs of one job, runs x cycles x legs x algorithms (under a minute of one core at 0.04 ms
    #: a leg, ``jik bench atlas``)
    max_work: int = 1_200_000
    #: legs of one job whose ends are sent back (3 numbers each in the JSON: about 12 MB)
    max_leg_ends: int = 200_000
    #: seconds a job is kept after it ends
    keep_for: float = 600.0
    #: seconds an ended job is kept at least, even when a new job needs its room
    min_keep: float = 60.0
    #: seconds a job may compute (then it fails, naming ``starts``: its legs may each run up to
    #: ``max_iterations`` steps, which ``max_work`` does not count)
    max_seconds: float = 600.0


def planned(req: AtlasRequest, limits: AtlasLimits) -> tuple[AtlasPlan, Used]:
    """The request's atlas, planned (curves traced), and what the job's response repeats: the
    robot used and the map the extended inverse used (None without it), as every run's
    response does; RequestError or InvalidInputError, each naming the field, when it cannot be."""
    if len(set(req.algorithms)) != len(req.algorithms):
        raise RequestError("algorithms", f"name each algorithm once, got {req.algorithms}")
    robot = request_robot(  # (each algorithm takes its own of the parameters)
        req.robot, req.augmentation, req.algorithms, req.algorithm_parameters, own=True
    )
    spec, inverses = robot.spec, robot.inverses
    try:
        path = req.path or spec.default_loop()
    except InvalidInputError as exc:
        raise RequestError("path", str(exc)) from None
    named = [(f"path[{i}]", v) for i, v in enumerate(path)]
    named += [(f"shifts[{i}]", v) for i, v in enumerate(req.shifts or [])]
    for name, v in named:
        check_length(spec, v, name)
    named = [(f"start_points[{i}]", v) for i, v in enumerate(req.start_points or [])]
    for name, x in [*named, ("reference", req.reference or spec.default_x0)]:  # (its default)
        check_length(spec, x, name, "p")
    gamma, mode = gamma_and_mode(spec, req)
    paths = len(req.shifts or [0]) * len(req.scales or [0])
    starts = len(req.start_points) if req.start_points else req.starts
    cycle = len(open_loop(np.asarray(path, dtype=float)))  # (the engine's legs of a cycle)
    legs = starts * paths * req.cycles * cycle * len(req.algorithms)
    if legs > limits.max_work:
        raise RequestError(
            "starts",
            f"starts x paths x cycles x legs x algorithms = {legs} is more than "
            f"{limits.max_work}; ask for fewer starts or cycles (or run `jik atlas` for larger "
            "atlases)",
        )
    if req.leg_ends and legs > limits.max_leg_ends:
        raise RequestError(
            "leg_ends",
            f"the ends of {legs} legs are more than the {limits.max_leg_ends} a "
            "response carries; ask for the drift alone or a smaller atlas",
        )
    try:
        plan = plan_atlas(
            inverses,
            path,
            cycles=req.cycles,
            n_starts=req.starts,
            starts=req.start_points,
            arc=req.arc or (-MAX_ARC, MAX_ARC),
            sampling=req.sampling,
            seed=req.seed,
            reference=req.reference or spec.default_x0,
            box=None if req.arc else spec.x_range,
            shifts=req.shifts,
            scales=req.scales,
            gamma=gamma,
            mode=mode,
            tol=req.tolerance,
            max_iterations=req.max_iterations,
        )
    except InvalidInputError as exc:
        head, dot, index = (exc.field or "").partition(".")
        if head != "starts":
            raise
        text = str(exc).replace("give the starts explicitly", "give start_points")
        if not req.start_points:
            raise RequestError("starts", text) from None
        # (the engine's starts are the request's start_points: its field names the entry)
        raise RequestError("start_points" + dot + index, without_field(text, exc.field)) from None
    return plan, (robot.robot, robot.augmentation)


@task(
    "reference",
    "another reference or path (eq. (7) from the reference to the path's first point ran out "
    "of memory)",
)
def plan_task(req: str, limits: AtlasLimits):
    """:func:`planned` of a request (JSON) as a compute worker's task, within the workers'
    time and memory limits (tracing the curves solves eq. (7)), its chunks sized for the pool
    (:func:`~jik.engine.atlas_run.sized_chunks`): the plan and what it used (:func:`planned`)
    and None, or None and the refusal (message, field), for the server to raise again."""
    try:
        plan, used = planned(AtlasRequest.model_validate_json(req), limits)
        return (sized_chunks(plan, CHUNK_SECONDS), used), None
    except InvalidInputError as exc:
        return None, (str(exc), exc.field)


def result_document(
    res: AtlasResult, arc, leg_ends: bool, period: float | None = None
) -> dict[str, Any]:
    """The fields of :class:`jik.app.compute.atlas_schemas.AtlasResult` (``period``: of the
    starts' closed self-motion curve, else None)."""
    algs = res.algorithms
    failures: dict[str, dict[str, str]] = {a: {} for a in algs}
    for (a, j, i), why in res.failures.items():
        failures[algs[a]][f"{j},{i}"] = why
    legs = res.leg_ends if leg_ends else None
    return {
        "algorithms": list(algs),
        "arc": list(arc),
        "paths": res.paths.tolist(),
        "parameter": [] if res.parameter is None else res.parameter.tolist(),
        "period": None if period is None else float(period),
        "starts": res.starts.tolist(),
        "drift": {a: nullable(res.drift[k]) for k, a in enumerate(algs)},
        "success": {a: res.success[k].tolist() for k, a in enumerate(algs)},
        "failures": failures,
        "leg_ends": None if legs is None else {a: nullable(legs[k]) for k, a in enumerate(algs)},
        "outside_limits": None
        if res.outside_limits is None
        else {a: int(res.outside_limits[k].sum()) for k, a in enumerate(algs)},
    }
