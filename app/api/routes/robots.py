"""GET /robots: the catalogue, enough for a client to build its controls."""

from fastapi import APIRouter

from ...compute.catalogue import robots_response
from ...compute.schemas import RobotsResponse
from ..dependencies import Pool

router = APIRouter(tags=["robots"])


@router.get("/robots", response_model=RobotsResponse)
async def robots(pool: Pool) -> RobotsResponse:
    """Every robot: p, r, parameter ranges, default start, target and path, and its
    augmentations with their parameters, ranges and defaults; plus the request limits."""
    return robots_response(pool.settings.timeout)
