"""POST /repeatability: a closed task-space path driven several times (Table 1)."""

from typing import Annotated

from fastapi import APIRouter, Body, Response

from ...compute.precheck import precheck
from ...compute.schemas import BUSY, RepeatabilityBody, RepeatabilityResponse
from ...compute.schemas.examples import openapi_examples
from ...compute.worker import repeatability_json
from ..dependencies import Pool

router = APIRouter(tags=["repeatability"])
#: The body, with every robot's example in the document (Swagger UI starts from the first).
RepeatabilityExamples = Annotated[
    RepeatabilityBody, Body(openapi_examples=openapi_examples("repeatability"))
]


@router.post(
    "/repeatability",
    response_model=RepeatabilityResponse,
    responses=BUSY,
)
async def repeatability(req: RepeatabilityExamples, pool: Pool) -> Response:
    """Configurations after each leg, at each cycle end, and the drift from x0 per cycle."""
    precheck(req)
    body = await pool.run(repeatability_json, req.model_dump_json().encode())
    return Response(body, media_type="application/json")
