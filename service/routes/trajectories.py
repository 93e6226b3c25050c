"""``POST /v1/trajectories``: plan one motion."""

from __future__ import annotations

from fastapi import APIRouter, Request

from service.planning import compare_request, plan_request, run_with_budget, trajectory_body
from service.problems import FiniteJSONResponse, problem_responses
from service.schemas.trajectories import CompareRequest, CompareResponse, TrajectoryRequest, TrajectoryResponse

router = APIRouter(prefix="/v1/trajectories", tags=["trajectories"])

_ERRORS = problem_responses(404, 422, 504)


@router.post(
    "",
    summary="Plan a timed trajectory",
    response_model=TrajectoryResponse,
    responses=_ERRORS,
)
async def create_trajectory(body: TrajectoryRequest, request: Request) -> FiniteJSONResponse:
    """Time the path of ``body`` for its robot under the requested limits and return the
    samples ``t, q, qd, qdd, tau``, the phase plane and the peak utilization of each limit."""
    settings = request.app.state.settings
    result = await run_with_budget(lambda deadline: plan_request(body, deadline), settings.plan_budget_s)
    return FiniteJSONResponse(trajectory_body(result))


@router.post("/compare", summary="Compare timing methods on one path", response_model=CompareResponse, responses=_ERRORS)
async def compare_trajectories(body: CompareRequest, request: Request) -> FiniteJSONResponse:
    """Time one path under several methods (e.g. ``phase_plane`` against ``quintic``) and return
    each one's duration, peak utilization and solve time: what time-optimality buys."""
    settings = request.app.state.settings
    result = await run_with_budget(lambda deadline: compare_request(body, deadline), settings.plan_budget_s)
    return FiniteJSONResponse(result)
