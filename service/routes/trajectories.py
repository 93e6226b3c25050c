"""``POST /v1/trajectories``: plan one motion."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse

from service.planning import plan_request, run_with_budget, trajectory_body
from service.schemas.common import Problem
from service.schemas.trajectories import TrajectoryRequest, TrajectoryResponse

router = APIRouter(prefix="/v1/trajectories", tags=["trajectories"])

_ERRORS = {404: {"model": Problem}, 413: {"model": Problem}, 422: {"model": Problem}, 504: {"model": Problem}}


@router.post(
    "",
    summary="Plan a timed trajectory",
    response_model=TrajectoryResponse,
    responses=_ERRORS,
)
async def create_trajectory(body: TrajectoryRequest, request: Request) -> JSONResponse:
    """Time the path of ``body`` for its robot under the requested limits and return the
    samples ``t, q, qd, qdd, tau``, the phase plane and the peak utilization of each limit."""
    settings = request.app.state.settings
    result = await run_with_budget(lambda deadline: plan_request(body, deadline), settings.plan_budget_s)
    return JSONResponse(trajectory_body(result))
