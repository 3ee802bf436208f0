"""POST /kinematics: k(x) and J(x) of any robot, to check a model against one's own tools."""

from typing import Annotated

from fastapi import APIRouter, Body, Response

from ...compute.kinematics import KinematicsBody, KinematicsResponse, kinematics_task
from ...compute.schemas import BUSY
from ...compute.schemas.examples import openapi_examples
from ..dependencies import Pool

router = APIRouter(tags=["kinematics"])
#: The body, with every robot's example in the document (Swagger UI starts from the first).
KinematicsExamples = Annotated[
    KinematicsBody, Body(openapi_examples=openapi_examples("kinematics"))
]


@router.post("/kinematics", response_model=KinematicsResponse, responses=BUSY)
async def kinematics(req: KinematicsExamples, pool: Pool) -> Response:
    """The robot's task coordinates k(x), eq. (4), and its analytic Jacobian J(x) at one
    configuration (``x`` a list of p numbers) or at each of a list of them. The robot is built
    in a compute worker, within its time and memory limits."""
    body = await pool.run(kinematics_task, req.model_dump_json().encode())
    return Response(body, media_type="application/json")
