"""``POST /v1/batches``: many requests as one job (``toptraj.service.jobs``, kind ``batch``), answered
by ``GET /v1/jobs/{id}`` like any job: in the server's own job worker process, or on the Ray
cluster the server is configured with (``TOPTRAJ_RAY_ADDRESS``). For thousands of requests,
``toptraj batch`` on a file is the tool."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import orjson
from fastapi import APIRouter, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import Response
from pydantic import BaseModel, ValidationError

from toptraj.service.field_hints import unknown_field_hint
from toptraj.service.locations import where
from toptraj.service.problems import LISTED_ERRORS
from toptraj.service.routes.jobs import _job_response, _problem, job_budget
from toptraj.service.schemas.jobs import BatchCreate, JobPublic
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest
from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(prefix="/v1/batches", tags=["jobs"], route_class=StrictJSONRoute)


def _checked(requests: list[dict]) -> None:
    """Each request against its schema (strictly, as the endpoints take them): a 422 naming
    the first bad one and its field; hints only for the errors a problem lists (``LISTED_ERRORS``)."""
    for index, item in enumerate(requests):
        schema = CompareRequest if "methods" in item else TrajectoryRequest
        try:
            schema.model_validate(item, strict=True)
        except ValidationError as error:
            errors = error.errors(include_url=False, include_context=False)
            raise RequestValidationError([_within(e, index, schema, rank < LISTED_ERRORS) for rank, e in enumerate(errors)]) from None


def _within(item: Mapping[str, Any], index: int, schema: type[BaseModel], hinted: bool = True) -> dict:
    """Error ``item`` of request ``index`` as an error of the batch's body; an unknown field's
    message with its hint from the request's own schema when ``hinted`` (the batch's holds the
    requests as objects of any shape)."""
    if item["type"] == "extra_forbidden" and hinted:
        item = {**item, "msg": item["msg"] + unknown_field_hint(schema, item["loc"], where(item["loc"]))}
    return {**item, "loc": ("body", "requests", index, *item["loc"])}


@router.post(
    "",
    status_code=202,
    summary="Start a batch of requests",
    response_model=JobPublic,
    responses={
        202: {"description": "Queued as a job; `GET` the `Location` for its progress and answers."},
        422: _problem(422, "A request of the batch does not fit its schema, or a budget over the maximum."),
        503: _problem(503, "The job queue is full (`Retry-After`)."),
    },
)
async def create_batch(body: BatchCreate, request: Request) -> Response:
    """Plan every request (trajectory or compare bodies) in the background as one job; the
    job's answer lists each request's status and body (its answer or its problem), in order.
    The answers are kept up to the server's answer cap (20 MB by default): once an answer does
    not fit, the job plans no more, and that request and the ones left each get a 422 saying
    how to submit them again."""
    _checked(body.requests)
    settings = request.app.state.settings
    budget_s = job_budget(settings, body.budget_s)
    runner = request.app.state.jobs
    from starlette.concurrency import run_in_threadpool

    job = await run_in_threadpool(
        runner.store.submit, "batch", orjson.dumps({"requests": body.requests}).decode(), budget_s, settings.job_queue
    )
    runner.wake()
    return _job_response(job, status_code=202, headers={"Location": f"/v1/jobs/{job.id}"})
