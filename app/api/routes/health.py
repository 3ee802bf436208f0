"""GET /health: liveness; never touches the compute pool."""

from fastapi import APIRouter

from ...compute.schemas import HealthResponse

router = APIRouter(tags=["health"])


@router.get("/health", response_model=HealthResponse)
async def health() -> dict:
    """``{"status": "ok"}`` while the server runs (answered even when every worker is busy)."""
    return {"status": "ok"}
