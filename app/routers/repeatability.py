"""POST /repeatability: a closed task-space path driven several times (Table 1)."""

from fastapi import APIRouter, Request

from app.schemas import BUSY, RepeatabilityRequest, RepeatabilityResponse

router = APIRouter(tags=["repeatability"])


@router.post(
    "/repeatability",
    response_model=RepeatabilityResponse,
    responses=BUSY,
)
async def repeatability(req: RepeatabilityRequest, request: Request) -> dict:
    """Configurations after each leg, at each cycle end, and the drift from x0 per cycle."""
    return await request.app.state.pool.run("repeatability", req.model_dump(mode="json"))
