"""``POST /v1/cells``: arms in one workspace, timed together."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Request
from fastapi.responses import Response

from toptraj.service.budget_advice import for_cell
from toptraj.service.cell_answers import csv_bytes
from toptraj.service.cells import plan_cell
from toptraj.service.formats import CSV_MEDIA_TYPE, chosen_format
from toptraj.service.planning import encode_json
from toptraj.service.problem_docs import problem_responses
from toptraj.service.schemas.cells import CellRequest
from toptraj.service.schemas.examples import cell_examples
from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(prefix="/v1/cells", tags=["cells"], route_class=StrictJSONRoute)
CSV_EXAMPLE = "t,arms[0].q.shoulder_pan_joint,…\n# robots: ur5, ur5\n# duration: 3.1 s\n…\n0.0,1.5,…\n"


@router.post(
    "",
    summary="Time arms sharing a workspace",
    responses=problem_responses(404, 413, 422, 503, 504)
    | {200: {"content": {"text/csv": {"schema": {"type": "string"}, "example": CSV_EXAMPLE}}}},
)
async def create_cell(body: Annotated[CellRequest, Body(openapi_examples=cell_examples())], request: Request) -> Response:
    """Time each arm along its own joint path so that the arms never come closer than
    `clearance`, all done as early as possible on one clock (path-velocity decomposition:
    two arms on the coordination diagram of their path parameters with the collision region
    marked; three or four by prioritized planning, each waiting at its start; each
    arm held by its own velocity, acceleration and torque limits, its payload and base pose
    included, waiting or slowing where needed). Returns every arm on the same times in the
    format asked (`format`: `samples`, one `joint_trajectory` per arm, or `csv`; CSV also when
    `Accept` prefers `text/csv`), each arm's peak utilization, the coordination diagram
    (`blocked` on the grid `s` x `s`, rows s1, and the `curve` taken), each arm's own optimum
    and the time lost to coordination. Errors: an unknown robot (404), a base rotation that is
    not one, a payload that is not physical, more than four arms, arms that collide at their
    start, an arm's path whose links touch (naming them and s), a torque no timing holds,
    paths that cannot pass each other (422); the heavy plannings' queue full (503, with
    `Retry-After`); past the budget (504).
    \f
    Runs in the heavy lane under the planning budget."""
    settings = request.app.state.settings
    format_ = chosen_format(body.format, request.headers.get("accept"))
    if format_ == "csv":
        content = await request.app.state.heavy_planning.run(
            lambda deadline: csv_bytes(plan_cell(body, deadline, "csv")),
            settings.plan_budget_s,
            advice=for_cell(),
        )
        return Response(content, media_type=CSV_MEDIA_TYPE)
    content = await request.app.state.heavy_planning.run(
        lambda deadline: encode_json(plan_cell(body, deadline)), settings.plan_budget_s, advice=for_cell()
    )
    return Response(content, media_type="application/json")
