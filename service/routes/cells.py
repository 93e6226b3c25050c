"""``POST /v1/cells``: two arms in one workspace, timed together."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Request
from fastapi.responses import Response

from toptraj.service.cells import plan_cell
from toptraj.service.planning import encode_json
from toptraj.service.problem_docs import problem_responses
from toptraj.service.schemas.cells import CellRequest
from toptraj.service.schemas.examples import cell_examples

router = APIRouter(prefix="/v1/cells", tags=["cells"])


@router.post("", summary="Time two arms sharing a workspace", responses=problem_responses(404, 413, 422, 504))
async def create_cell(body: Annotated[CellRequest, Body(openapi_examples=cell_examples())], request: Request) -> Response:
    """Time each arm along its own joint path so that the arms never come closer than
    `clearance`, both done as early as possible on one clock (path-velocity decomposition:
    the coordination diagram of the two path parameters with the collision region marked, each
    arm held by its own limits, waiting or slowing where needed). Returns both trajectories on
    the same times (one JointTrajectory per arm), the coordination diagram (`blocked` on the
    grid `s` x `s`, rows s1, and the `curve` taken), each arm's own optimum and the time lost
    to coordination. Errors: an unknown robot (404), a base rotation that is not one, more than
    two arms, arms that collide at their start, paths that cannot pass each other (422).
    \f
    Runs in the heavy lane under the planning budget."""
    settings = request.app.state.settings
    content = await request.app.state.heavy_planning.run(
        lambda deadline: encode_json(plan_cell(body, deadline)), settings.plan_budget_s
    )
    return Response(content, media_type="application/json")
