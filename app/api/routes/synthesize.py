"""POST /synthesize: an augmenting map h on a box, synthesized or from the catalogue."""

from typing import Annotated

from fastapi import APIRouter, Body, Response

from ...compute.precheck import precheck
from ...compute.schemas import (
    BUSY,
    SynthesisMethodsResponse,
    SynthesizeBody,
    SynthesizeResponse,
)
from ...compute.schemas.examples import openapi_examples
from ...compute.synthesis import synthesis_methods
from ...compute.worker import synthesize_json
from ..dependencies import Pool

router = APIRouter(tags=["synthesize"])
#: The body, with every robot's example in the document (Swagger UI starts from the first).
SynthesizeExamples = Annotated[
    SynthesizeBody, Body(openapi_examples=openapi_examples("synthesize"))
]


@router.get("/synthesize", response_model=SynthesisMethodsResponse)
async def methods() -> SynthesisMethodsResponse:
    """The synthesis methods this server offers, with a note on each."""
    return synthesis_methods()


@router.post(
    "/synthesize",
    response_model=SynthesizeResponse,
    responses=BUSY,
)
async def synthesize(req: SynthesizeExamples, pool: Pool) -> Response:
    """h on a grid of the box, its coefficients and E1, E2 over the box."""
    precheck(req)
    body = await pool.run(synthesize_json, req.model_dump_json().encode())
    return Response(body, media_type="application/json")
