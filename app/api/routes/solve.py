"""POST /solve: one run of the continuation algorithm (7), micro-batched with its neighbours."""

from typing import Annotated

from fastapi import APIRouter, Body, Response

from ...compute.schemas import BUSY, SolveBody, SolveResponse
from ...compute.schemas.examples import openapi_examples
from ..dependencies import Pool

router = APIRouter(tags=["solve"])
#: The body, with every robot's example in the document (Swagger UI starts from the first).
SolveExamples = Annotated[SolveBody, Body(openapi_examples=openapi_examples("solve"))]


@router.post(
    "/solve",
    response_model=SolveResponse,
    responses=BUSY,
)
async def solve(req: SolveExamples, pool: Pool) -> Response:
    """Solve k(x) = target from x0 with the pseudoinverse (8) or the extended inverse (11).

    The body comes from a worker as the JSON of a ``SolveResponse``. Under ``create_app()``
    well-formed JSON requests are answered by :class:`jik.app.api.fastpath.SolveFastPath` with
    the same pool and error mapping; this route describes the endpoint and answers everything
    else.
    """
    body = await pool.solve(req)
    return Response(body, media_type="application/json")
