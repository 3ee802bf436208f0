"""POST /repeatability: a closed task-space path driven several times (Table 1)."""

from fastapi import APIRouter, Response

from jik.app.api.dependencies import Pool
from jik.app.compute.precheck import precheck
from jik.app.compute.schemas import BUSY, RepeatabilityBody, RepeatabilityResponse
from jik.app.compute.worker import repeatability_json

router = APIRouter(tags=["repeatability"])


@router.post(
    "/repeatability",
    response_model=RepeatabilityResponse,
    responses=BUSY,
)
async def repeatability(req: RepeatabilityBody, pool: Pool) -> Response:
    """Configurations after each leg, at each cycle end, and the drift from x0 per cycle."""
    precheck(req)
    body = await pool.run(repeatability_json, req.model_dump_json().encode())
    return Response(body, media_type="application/json")
