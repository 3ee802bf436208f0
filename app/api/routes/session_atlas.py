"""A dashboard session's repeatability atlas: ``POST /api/sessions/{id}/atlas`` starts the atlas
of the session's current state, ``GET /api/sessions/{id}/atlas/{job}`` follows it and, once
done, gives its heatmap, ``GET .../atlas/{job}/table.csv`` its table (of the session's own jobs
alone: another tab's atlas is not there for it); ``DELETE /atlas/{job}`` cancels it.

The atlas is a job of the REST API's :class:`jik.app.compute.atlas_jobs.AtlasJobs`, with its
request model and limits (jobs per client, one computing at once): the session only says which
atlas its state asks for (:func:`jik.app.dashboard.atlas.atlas_request`).
"""

from __future__ import annotations

import json
from typing import Annotated

from fastapi import APIRouter, Request, Response
from fastapi.responses import JSONResponse, StreamingResponse
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from starlette.concurrency import run_in_threadpool

from ...compute.atlas_jobs import AtlasJob, AtlasJobNotFound
from ...compute.atlas_schemas import MAX_CYCLES, MAX_FAMILY, AtlasJobResponse, Scale
from ...compute.schemas import INTEGRAL
from ...compute.schemas.wording import refused
from ...compute.user_robots import echo
from ...dashboard.atlas import atlas_figure, atlas_request
from ...dashboard.plotting import figure_json
from ..dependencies import Store
from .atlas import ERRORS, TABLE, EveryLeg, Jobs, start_job, table_response

router = APIRouter(tags=["dashboard sessions"])
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


@router.post(
    "/api/sessions/{session_id}/atlas",
    status_code=202,
    response_model=AtlasJobResponse,
    responses={**ERRORS, **_NOT_FOUND},
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


@router.get("/api/sessions/{session_id}/atlas/{job_id}", responses={**ERRORS, **_NOT_FOUND})
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


@router.get(
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
    (:func:`jik.app.compute.user_robots.echo`), never sent back."""
    robot = request.get("robot")
    return {**request, "robot": echo(robot)} if isinstance(robot, dict) else request
