"""``POST /v1/trajectories``: plan one motion."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Request
from fastapi.responses import Response

from toptraj.service.budget_advice import as_job
from toptraj.service.planning import compare_request, encode_json, heavy_request, plan_request, render, worth_a_leash
from toptraj.service.problem_docs import problem_responses
from toptraj.service.schemas.answers import CompareResponse, TrajectoryResponse
from toptraj.service.schemas.examples import openapi_examples
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest
from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(prefix="/v1/trajectories", tags=["trajectories"], route_class=StrictJSONRoute)

_ERRORS = problem_responses(404, 413, 422, 503, 504)


@router.post(
    "",
    summary="Plan a timed trajectory",
    response_model=TrajectoryResponse,
    responses={
        200: {"content": {"text/csv": {"schema": {"type": "string"}, "example": "t,q.shoulder,…\n# robot: ur5\n# method: phase_plane\n…\n0.0,0.0,…\n"}}},
        **_ERRORS,
    },
)
async def create_trajectory(
    body: Annotated[TrajectoryRequest, Body(openapi_examples=openapi_examples(compare=False))], request: Request
) -> Response:
    """Time the path of the request for its robot under the requested limits and return the
    samples `t, q, qd, qdd, tau`, the phase plane and the peak utilization of each limit, in
    the format asked (`output.format`; CSV also when `Accept` prefers `text/csv`). Planning has
    a time budget (504 past it; `POST /v1/jobs` runs longer ones in the background). Heavy
    plannings (`search`, `collocation`, `jerk_limited`, any free path, `min_cost` on its
    default grid or on more than 100 intervals) wait for capacity of their own, so that short
    requests never queue behind them.
    \f
    The body is built and encoded by the planning, within the time budget; a small request
    (``worth_a_leash``) is first tried on the event loop, a heavy one (``heavy_request``) waits
    for a heavy worker of its own."""
    settings = request.app.state.settings

    accept = request.headers.get("accept")

    def planned(deadline) -> tuple[bytes, str]:
        return render(plan_request(body, deadline, settings.max_response_bytes, accept, settings.search_memory_bytes), body, accept)

    advice = as_job("trajectory", settings.plan_budget_s, settings.job_budget_s, settings.job_max_budget_s)
    if heavy_request(body):  # admitted apart, so that it never holds up the short requests
        content, media_type = await request.app.state.heavy_planning.run(planned, settings.plan_budget_s, advice=advice, busy_advice=advice)
    else:
        content, media_type = await request.app.state.planning.run(
            planned, settings.plan_budget_s, leashed=worth_a_leash(body), advice=advice
        )
    return Response(content, media_type=media_type)


@router.post("/compare", summary="Compare timing methods on one path", response_model=CompareResponse, responses=_ERRORS)
async def compare_trajectories(
    body: Annotated[CompareRequest, Body(openapi_examples=openapi_examples(compare=True))], request: Request
) -> Response:
    """Time one path under several methods (e.g. ``phase_plane`` against ``quintic``) and return
    each one's duration, peak utilization and solve time: what time-optimality buys."""
    settings = request.app.state.settings
    lane = request.app.state.heavy_planning if heavy_request(body) else request.app.state.planning
    advice = as_job("compare", settings.plan_budget_s, settings.job_budget_s, settings.job_max_budget_s)
    content = await lane.run(
        lambda deadline: encode_json(compare_request(body, deadline)), settings.plan_budget_s, advice=advice,
        busy_advice=advice if lane is request.app.state.heavy_planning else "",
    )
    return Response(content, media_type="application/json")
