"""The computing endpoints, each a task of the compute pool: POST /solve (one run of the
continuation algorithm (7), micro-batched with its neighbours), POST /repeatability (a closed
task-space path driven several times, Table 1), GET and POST /synthesize (an augmenting map h on
a box, synthesized or from the catalogue) and POST /kinematics (k(x) and J(x) of any robot, to
check a model against one's own tools); GET /robots, the catalogue, enough for a client to build
its controls; GET /health, liveness, which never touches the compute pool.

Each body lists every robot's example in the document (Swagger UI starts from the first).
"""

from typing import Annotated

from fastapi import APIRouter, Body, Response

from ...compute.catalogue import robots_response
from ...compute.kinematics import KinematicsBody, KinematicsResponse, kinematics_task
from ...compute.requests import precheck
from ...compute.schemas import (
    BUSY,
    HealthResponse,
    RepeatabilityBody,
    RepeatabilityResponse,
    RobotsResponse,
    SolveBody,
    SolveResponse,
    SynthesisMethodsResponse,
    SynthesizeBody,
    SynthesizeResponse,
)
from ...compute.schemas.examples import openapi_examples
from ...compute.synthesis import synthesis_methods
from ...compute.worker import repeatability_json, synthesize_json
from ..dependencies import Pool

router = APIRouter()
SolveExamples = Annotated[SolveBody, Body(openapi_examples=openapi_examples("solve"))]
RepeatabilityExamples = Annotated[
    RepeatabilityBody, Body(openapi_examples=openapi_examples("repeatability"))
]
SynthesizeExamples = Annotated[
    SynthesizeBody, Body(openapi_examples=openapi_examples("synthesize"))
]
KinematicsExamples = Annotated[
    KinematicsBody, Body(openapi_examples=openapi_examples("kinematics"))
]


@router.get("/health", response_model=HealthResponse, tags=["health"])
async def health() -> dict:
    """``{"status": "ok"}`` while the server runs (answered even when every worker is busy)."""
    return {"status": "ok"}


@router.get("/robots", response_model=RobotsResponse, tags=["robots"])
async def robots(pool: Pool) -> RobotsResponse:
    """Every robot: p, r, parameter ranges, default start, target and path, and its
    augmentations with their parameters, ranges and defaults; plus the request limits."""
    return robots_response(pool.settings.timeout)


@router.post("/solve", response_model=SolveResponse, responses=BUSY, tags=["solve"])
async def solve(req: SolveExamples, pool: Pool) -> Response:
    """Solve k(x) = target from x0 with the pseudoinverse (8) or the extended inverse (11).

    The body comes from a worker as the JSON of a ``SolveResponse``. Under ``create_app()``
    well-formed JSON requests are answered by :class:`jik.app.api.fastpath.SolveFastPath` with
    the same pool and error mapping; this route describes the endpoint and answers everything
    else.
    """
    body = await pool.solve(req)
    return Response(body, media_type="application/json")


@router.post(
    "/repeatability", response_model=RepeatabilityResponse, responses=BUSY, tags=["repeatability"]
)
async def repeatability(req: RepeatabilityExamples, pool: Pool) -> Response:
    """Configurations after each leg, at each cycle end, and the drift from x0 per cycle."""
    precheck(req)
    body = await pool.run(repeatability_json, req.model_dump_json().encode())
    return Response(body, media_type="application/json")


@router.get("/synthesize", response_model=SynthesisMethodsResponse, tags=["synthesize"])
async def methods() -> SynthesisMethodsResponse:
    """The synthesis methods this server offers, with a note on each."""
    return synthesis_methods()


@router.post("/synthesize", response_model=SynthesizeResponse, responses=BUSY, tags=["synthesize"])
async def synthesize(req: SynthesizeExamples, pool: Pool) -> Response:
    """h on a grid of the box, its coefficients and E1, E2 over the box."""
    precheck(req)
    body = await pool.run(synthesize_json, req.model_dump_json().encode())
    return Response(body, media_type="application/json")


@router.post("/kinematics", response_model=KinematicsResponse, responses=BUSY, tags=["kinematics"])
async def kinematics(req: KinematicsExamples, pool: Pool) -> Response:
    """The robot's task coordinates k(x), eq. (4), and its analytic Jacobian J(x) at one
    configuration (``x`` a list of p numbers) or at each of a list of them. The robot is built
    in a compute worker, within its time and memory limits."""
    body = await pool.run(kinematics_task, req.model_dump_json().encode())
    return Response(body, media_type="application/json")
