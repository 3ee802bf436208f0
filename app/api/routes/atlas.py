"""Repeatability atlases as background jobs: ``/atlas`` for the REST API, and
``/api/sessions/{id}/atlas`` for a dashboard session's current state.

A job is planned and started by POST (202 with its id; 422 for bad input, 429 past the limits),
read by GET (progress, then the result; ``/table.csv``: the result as the engine's table), and
cancelled by DELETE (204). The jobs live in the app's
:class:`jik.app.compute.atlas_jobs.AtlasJobs` and outlive the requests that made them. A job's
id is a random token: whoever has it reads the job, and no one else.

A session's atlas is a job like the API's, with its request model and limits (jobs per client,
the session being its client, one computing at once): the session only says which atlas its
state asks for (:func:`jik.app.dashboard.atlas.atlas_request`), and its GET gives the heatmap
once done. A session reads its own jobs alone: another tab's atlas is not there for it.
"""

from __future__ import annotations

import json
import re
from typing import Annotated

from fastapi import APIRouter, Body, Depends, Query, Request, Response
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, StreamingResponse
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from starlette.concurrency import run_in_threadpool

from ....engine.exceptions import InvalidInputError
from ...compute.atlas_jobs import AtlasJob, AtlasJobNotFound, AtlasJobs
from ...compute.atlas_plan import AtlasLimits, plan_task
from ...compute.atlas_schemas import MAX_CYCLES, MAX_FAMILY, AtlasBody, AtlasJobResponse, Scale
from ...compute.pool import ComputePool
from ...compute.robot_requests import echo
from ...compute.schemas import INTEGRAL, ErrorResponse
from ...compute.schemas.examples import openapi_examples
from ...compute.schemas.wording import refused
from ...dashboard.atlas import atlas_figure, atlas_request
from ...dashboard.plotting import figure_json
from ..dependencies import Store

router = APIRouter(tags=["atlas"])
session_router = APIRouter(tags=["dashboard sessions"])
#: The body, with every robot's example in the document (Swagger UI starts from the first).
AtlasExamples = Annotated[AtlasBody, Body(openapi_examples=openapi_examples("atlas"))]


def jobs_of(request: Request) -> AtlasJobs:
    """The app's atlas jobs (made on first use; their chunks run in the compute pool)."""
    jobs = getattr(request.app.state, "atlas_jobs", None)
    if jobs is None:
        jobs = request.app.state.atlas_jobs = AtlasJobs(AtlasLimits(), request.app.state.pool)
    return jobs


async def start_job(
    jobs: AtlasJobs, request: Request, response: Response, req, session: str | None = None
) -> AtlasJobResponse:
    """Plan ``req`` in a worker of the app's compute pool (tracing the self-motion curves solves
    eq. (7): within the workers' time and memory limits, like any computation a request asks
    for), then start it as a job of the client's address (``session``: of that dashboard
    session's, which tabs behind one address, SSH tunnels or a NAT, each have: see
    :class:`~jik.app.compute.atlas_plan.AtlasLimits`); the 202's body, its ``Location`` the
    job's ``/atlas/{job_id}``."""
    client = request.client.host if request.client else "unknown"
    jobs.check_room(client, session)  # (before the work)
    pool: ComputePool = request.app.state.pool
    plan, refused = await pool.run(plan_task, req.model_dump_json(), jobs.limits)
    if refused is not None:  # (the engine's message and field)
        raise InvalidInputError(*refused)
    job = await run_in_threadpool(jobs.start, client, req, plan, session)
    response.headers["Location"] = f"/atlas/{job.id}"
    return jobs.response(job)


Jobs = Annotated[AtlasJobs, Depends(jobs_of)]
ERRORS: dict[int | str, dict] = {
    404: {
        "model": ErrorResponse,
        "description": "no such job (cancelled, ended, or lost in a restart)",
    },
    429: {"model": ErrorResponse, "description": "too many atlas jobs; retry later"},
}
#: The 202 of a started job: its address in Location.
STARTED: dict[int | str, dict] = {
    202: {"headers": {"Location": {"description": "/atlas/{job_id}", "schema": {"type": "string"}}}}
}
EveryLeg = Annotated[
    bool,
    Query(
        description="a row per leg's end instead of per cycle (needs a job with leg_ends); "
        "422 when the job did not keep them"
    ),
]
#: The table's answers: the CSV once the job is done, else the job's state.
TABLE: dict[int | str, dict] = {
    200: {
        "description": "the atlas's table, a row per run, algorithm and cycle (or leg), "
        "columns named as the engine's AtlasResult.columns() names them; while the job is not "
        "done (queued, running, failed), its state as GET /atlas/{job_id} gives it, as JSON",
        "content": {
            "text/csv": {"schema": {"type": "string"}},
            "application/json": {"schema": {"$ref": "#/components/schemas/AtlasJobResponse"}},
        },
    },
}


def table_response(jobs: AtlasJobs, job: AtlasJob, every_leg: bool) -> Response:
    """The done job's table as CSV (:meth:`jik.engine.atlas_table.AtlasResult.csv_text`,
    streamed a block of rows at a time from the atlas the job keeps); before that, the job's
    state (JSON, as ``GET /atlas/{job_id}`` answers it)."""
    if job.status != "done" or job.atlas is None:
        return JSONResponse(jobs.response(job).model_dump(mode="json"))
    try:
        text = job.atlas.csv_text(every_leg)
    except InvalidInputError as exc:
        error = {"loc": ("query", "every_leg"), "msg": str(exc), "type": "value_error"}
        raise RequestValidationError([error]) from None
    robot = re.sub(r"[^A-Za-z0-9_.-]", "_", job.used[0].name)
    name = f"jik-{robot}-atlas-{job.id}{'-legs' * every_leg}.csv"
    return StreamingResponse(
        text,
        media_type="text/csv",
        headers={"Content-Disposition": f'attachment; filename="{name}"'},
    )


@router.post(
    "/atlas", status_code=202, response_model=AtlasJobResponse, responses={**ERRORS, **STARTED}
)
async def start_atlas(req: AtlasExamples, request: Request, response: Response, jobs: Jobs):
    """Plan the atlas (the self-motion curves are traced here) and start it as a job."""
    return await start_job(jobs, request, response, req)


@router.get("/atlas/{job_id}", response_model=AtlasJobResponse, responses=ERRORS)
async def read_atlas(job_id: str, jobs: Jobs):
    """The job's status and progress; its result once done."""
    return jobs.response(jobs.get(job_id))


@router.get(
    "/atlas/{job_id}/table.csv",
    response_class=StreamingResponse,
    responses={**ERRORS, **TABLE},
)
async def read_atlas_table(job_id: str, jobs: Jobs, every_leg: EveryLeg = False) -> Response:
    """The done job's atlas as one long table (CSV): the engine's ``AtlasResult.columns()``,
    whose docstring names the columns, with cells as ``jik atlas --csv`` writes them."""
    return table_response(jobs, jobs.get(job_id), every_leg)


@router.delete("/atlas/{job_id}", status_code=204, responses=ERRORS)
async def cancel_atlas(job_id: str, jobs: Jobs) -> Response:
    """Cancel the job (it stops after the chunk it is on) and forget it."""
    jobs.cancel(job_id)
    return Response(status_code=204)


#: Largest atlas the panel asks for (the API's own limits apply too).
MAX_PANEL_STARTS = 4096
_NOT_FOUND: dict[int | str, dict] = {404: {"description": "no such session or atlas job"}}


class SessionAtlas(BaseModel):
    """The atlas of the session's current state: how many starts and cycles, which scales."""

    model_config = ConfigDict(
        extra="forbid", json_schema_extra={"examples": [{"starts": 16, "scales": [1.0, 0.5]}]}
    )

    starts: Annotated[int, Field(strict=True, ge=2, le=MAX_PANEL_STARTS), INTEGRAL] = 256
    cycles: Annotated[int, Field(strict=True, ge=1, le=MAX_CYCLES), INTEGRAL] | None = Field(
        None, description="default: the session's cycles"
    )
    scales: Annotated[list[Scale], Field(min_length=1, max_length=MAX_FAMILY)] | None = Field(
        None, description="scales of the path about k(x0), a row of the heatmap each"
    )


@session_router.post(
    "/api/sessions/{session_id}/atlas",
    status_code=202,
    response_model=AtlasJobResponse,
    responses={**ERRORS, **_NOT_FOUND, **STARTED},
)
async def start_session_atlas(
    session_id: str,
    body: SessionAtlas,
    request: Request,
    response: Response,
    store: Store,
    jobs: Jobs,
):
    """Start the atlas of the session's current state (422 naming the field it refuses)."""
    state = store.get(session_id).dashboard.state
    try:
        req = atlas_request(state, body.starts, body.cycles, body.scales)
    except ValidationError as exc:
        error = exc.errors()[0]
        name = ".".join(str(p) for p in error["loc"]) or "state"
        raise refused(name, error["msg"]) from None
    store.when_ended(jobs.cancel_session)  # (the session's jobs end with it)
    return await start_job(jobs, request, response, req, session_id)


@session_router.get("/api/sessions/{session_id}/atlas/{job_id}", responses={**ERRORS, **_NOT_FOUND})
async def read_session_atlas(session_id: str, job_id: str, store: Store, jobs: Jobs):
    """The job's status and progress; once done, its heatmap (a plotly figure), the starts and
    the paths (a cell's run, path * N + start, picks one of each), and the request; 404 for a
    job of another session or of the REST API."""
    job = _own_job(store, jobs, session_id, job_id)
    body = jobs.response(job).model_dump(mode="json", exclude={"result"})
    if job.status == "done" and job.result is not None:
        figure = await run_in_threadpool(atlas_figure, job.result, job.request, job.used[0])
        body.update(
            figure=json.loads(figure_json(figure)),
            starts=job.result["starts"],
            paths=job.result["paths"],
            request=_echoed(job.request.model_dump(mode="json")),
        )
    return JSONResponse(body)


@session_router.get(
    "/api/sessions/{session_id}/atlas/{job_id}/table.csv",
    response_class=StreamingResponse,
    responses={**ERRORS, **_NOT_FOUND, **TABLE},
)
async def read_session_atlas_table(
    session_id: str, job_id: str, store: Store, jobs: Jobs, every_leg: EveryLeg = False
) -> Response:
    """The table of an atlas this session started (the panel's CSV): the same CSV as
    ``GET /atlas/{job_id}/table.csv``; 404 for a job of another session or of the REST API."""
    return table_response(jobs, _own_job(store, jobs, session_id, job_id), every_leg)


def _own_job(store: Store, jobs: Jobs, session_id: str, job_id: str) -> AtlasJob:
    """The job ``job_id`` if the session ``session_id`` started it: a tab reads only its own
    atlases (404, as for a job that is not there, otherwise)."""
    store.get(session_id)
    job = jobs.get(job_id)
    if job.session != session_id:
        raise AtlasJobNotFound(job_id, "this session did not start it")
    return job


def _echoed(request: dict) -> dict:
    """The request as a response repeats it: a URDF robot's text named by its size and SHA-256
    (:func:`jik.app.compute.robot_requests.echo`), never sent back."""
    robot = request.get("robot")
    return {**request, "robot": echo(robot)} if isinstance(robot, dict) else request
