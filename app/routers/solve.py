"""POST /solve: one run of the continuation algorithm (7), micro-batched with its neighbours."""

from fastapi import APIRouter, Request

from app.schemas import BUSY, SolveRequest, SolveResponse

router = APIRouter(tags=["solve"])


@router.post(
    "/solve",
    response_model=SolveResponse,
    responses=BUSY,
)
async def solve(req: SolveRequest, request: Request) -> dict:
    """Solve k(x) = target from x0 with the pseudoinverse (8) or the extended inverse (11)."""
    return await request.app.state.pool.solve(req)
