"""``/v1/jobs``: trajectories and comparisons computed in the background, under a budget of
their own, with progress; the answer (or the error) is kept in the job store."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Annotated

import orjson
from fastapi import APIRouter, Body, Query, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import Response
from pydantic import ValidationError
from starlette.concurrency import run_in_threadpool

from toptraj import robots
from toptraj.robots.errors import ToptrajError, excerpt
from toptraj.service.formats import CSV_MEDIA_TYPE, chosen_format, csv_bytes
from toptraj.service.jobs import job_answer_bytes
from toptraj.service.jobs.records import Job, JobEnded
from toptraj.service.jobs.store import JobStore
from toptraj.service.planning import check_request
from toptraj.service.problem_docs import PROBLEM_JSON, problem_responses
from toptraj.service.problems import RequestRefused
from toptraj.service.schemas.jobs import JobCreate, JobList, JobPublic, JobStatus
from toptraj.service.schemas.trajectories import TrajectoryRequest
from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(prefix="/v1/jobs", tags=["jobs"], route_class=StrictJSONRoute)

#: Most jobs on one page of ``GET /v1/jobs``.
MAX_PAGE = 100


class UnknownJob(ToptrajError):
    """No job has that id (it never existed, or it ended long enough ago to be deleted)."""

    status = 404
    title = "Unknown job"


class JobNotDone(ToptrajError):
    """The job has no answer: it has not ended, or it ended without one."""

    status = 409
    title = "Job has no answer"


def _problem(status: int, description: str) -> dict:
    return {**problem_responses(status)[status], "description": description}


_UR5 = [[0, -1.2, 1, 0, 0, 0], [0.8, -1, 1.4, -0.5, 0.6, 0.3], [2, -1.3, 1.2, 0.2, 0.4, 1.2]]
EXAMPLES = {
    "free_path": {
        "summary": "A free-path collocation (tens of seconds)",
        "value": {
            "trajectory": {
                "robot": "geering_2r",
                "path": {"kind": "free", "start": [0.0, 0.0], "goal": [0.76, 0.0]},
                "timing": {"method": "collocation", "constraints": ["torque"]},
                "output": {"dt": 0.01},
            },
            "budget_s": 600,
        },
    },
    "trajectory": {
        "summary": "A trajectory, as POST /v1/trajectories",
        "value": {
            "trajectory": {
                "robot": "ur5",
                "path": {"kind": "waypoints", "waypoints": _UR5},
                "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
            }
        },
    },
    "compare": {
        "summary": "A comparison, as POST /v1/trajectories/compare",
        "value": {
            "compare": {
                "robot": "ur5",
                "path": {"kind": "waypoints", "waypoints": _UR5},
                "methods": ["phase_plane", "min_cost", "quintic"],
            }
        },
    },
}


def _time(value: float | None) -> str | None:
    return None if value is None else datetime.fromtimestamp(value, UTC).isoformat()


def job_fields(job: Job) -> dict:
    """The public fields of ``job`` but its answer (``JobSummary``)."""
    return {
        "id": job.id,
        "kind": job.kind,
        "status": job.status,
        "progress": {"fraction": job.fraction, "stage": job.stage},
        "budget_s": job.budget_s,
        "created_at": _time(job.created),
        "started_at": _time(job.started),
        "finished_at": _time(job.finished),
        "error": job.error,
    }


def _job_response(job: Job, result: bytes | None = None, status_code: int = 200, headers: dict | None = None) -> Response:
    """``JobPublic`` as JSON; the stored answer is inserted as it is (no decoding)."""
    body = {**job_fields(job), "result": None if result is None else orjson.Fragment(result)}
    return Response(orjson.dumps(body), status_code=status_code, media_type="application/json", headers=headers)


def _store(request: Request) -> JobStore:
    return request.app.state.jobs.store


def _job(store: JobStore, job_id: str) -> Job:
    job = store.get(job_id)
    if job is None:
        raise UnknownJob(
            f"no job has id {excerpt(job_id)}; ids are 32 hex digits from POST /v1/jobs (jobs that "
            "ended are kept for a while, then deleted)"
        )
    return job


async def _strictly(request: Request) -> None:
    """Validate the body again without type coercion, as the OpenAPI declares it: a JSON
    ``true`` or ``"0.1"`` is not a number. (A job's request is stored and computed later; what
    is stored is what the schema allows.)

    Raises:
        RequestValidationError: a 422 naming each field, as for any malformed body.
    """
    try:
        JobCreate.model_validate(await request.json(), strict=True)
    except ValidationError as error:
        raise RequestValidationError(
            [{**item, "loc": ("body", *item["loc"])} for item in error.errors(include_url=False, include_context=False)]
        ) from None


def job_budget(settings, asked: float | None) -> float:
    """The budget (s) of a job or batch asking ``asked`` (``None``: the server's default, within
    its maximum); ``RequestRefused`` above the maximum."""
    budget_s = min(settings.job_budget_s, settings.job_max_budget_s) if asked is None else asked
    if budget_s > settings.job_max_budget_s:
        raise RequestRefused(
            f"budget_s = {budget_s:g} s is more than this server allows: use budget_s <= "
            f"{settings.job_max_budget_s:g} (setting TOPTRAJ_JOB_MAX_BUDGET_S)"
        )
    return budget_s


@router.post(
    "",
    status_code=202,
    summary="Start a background job",
    response_model=JobPublic,
    responses={
        202: {
            "description": "Queued; `GET` the `Location` for its progress and answer.",
            "headers": {"Location": {"description": "`/v1/jobs/{id}`", "schema": {"type": "string"}}},
        },
        404: _problem(404, "No robot has that name."),
        422: _problem(422, "Malformed request, a budget_s over the server's maximum, or a trajectory the planner refuses before any work."),
        503: _problem(503, "The job queue is full (`Retry-After`), or the job store cannot be written."),
    },
)
async def create_job(body: Annotated[JobCreate, Body(openapi_examples=EXAMPLES)], request: Request) -> Response:
    """Compute a trajectory (the body of `POST /v1/trajectories` under `trajectory`) or a
    comparison (the body of `POST /v1/trajectories/compare` under `compare`) in the background,
    under a budget of its own (`budget_s`). Answers 202 at once with the job and its `Location`.
    The answer, once `done`, is the very body the synchronous endpoint would give."""
    await _strictly(request)
    settings = request.app.state.settings
    budget_s = job_budget(settings, body.budget_s)
    runner = request.app.state.jobs
    if body.trajectory is not None:  # refused now as the synchronous endpoint would before any work, not minutes later
        await run_in_threadpool(check_request, body.trajectory, job_answer_bytes(settings), settings.search_memory_bytes)
    else:  # a comparison answers each method's refusal in its entry, as its endpoint does
        await run_in_threadpool(robots.load, body.request.robot)  # an unknown robot is a 404 now, not a failed job
    request_json = body.request.model_dump_json(exclude_unset=True)  # what was given: its rules read again as given
    job = await run_in_threadpool(runner.store.submit, body.kind, request_json, budget_s, settings.job_queue)
    runner.wake()
    return _job_response(job, status_code=202, headers={"Location": f"/v1/jobs/{job.id}"})


@router.get("", summary="List recent jobs", response_model=JobList, responses={422: _problem(422, "A bad cursor or limit.")})
def list_jobs(
    request: Request,
    limit: Annotated[int, Query(ge=1, le=MAX_PAGE, description="Jobs per page.")] = 20,
    cursor: Annotated[str | None, Query(max_length=20, description="`next_cursor` of the previous page.")] = None,
    status: Annotated[JobStatus | None, Query(description="Only jobs with this status.")] = None,
) -> Response:
    """The jobs the store keeps, newest first, without their answers, a page at a time."""
    before = None
    if cursor is not None:
        if not (cursor.isascii() and cursor.isdigit()) or int(cursor) >= 2**63:  # "²" is a digit to isdigit
            raise RequestRefused(f"cursor {excerpt(cursor)} is not a next_cursor of GET /v1/jobs")
        before = int(cursor)
    jobs = _store(request).jobs(limit + 1, before, status)
    page = jobs[:limit]
    body = {"jobs": [job_fields(job) for job in page], "next_cursor": str(page[-1].seq) if len(jobs) > limit else None}
    return Response(orjson.dumps(body), media_type="application/json")


@router.get(
    "/{job_id}",
    summary="A job's status, progress and answer",
    response_model=JobPublic,
    responses={404: _problem(404, "No job has that id.")},
)
def get_job(job_id: str, request: Request) -> Response:
    """Status, progress and timestamps; once `done`, the `result` (the synchronous endpoint's
    body); once `failed`, the `error` (its problem+json object)."""
    store = _store(request)
    job = _job(store, job_id)
    return _job_response(job, store.result(job_id) if job.status == "done" else None)


@router.get(
    "/{job_id}/result",
    summary="A job's answer alone",
    response_model=None,
    responses={
        200: {"description": "The body of the synchronous endpoint (`TrajectoryResponse` or `CompareResponse`), in "
                             "the trajectory's `output.format`: CSV when it asked `csv`, or when it asked the default "
                             "and the `Accept` header prefers `text/csv`.",
              "content": {"application/json": {"schema": {"type": "object"}},
                          "text/csv": {"schema": {"type": "string"}, "example": "t,q.shoulder,…\n# robot: ur5\n…\n0.0,0.0,…\n"}}},
        404: _problem(404, "No job has that id."),
        409: _problem(409, "The job has not ended, or ended without an answer (cancelled, interrupted)."),
        422: _problem(422, "The job failed: its own error, with the status it carries (e.g. 422)."),
        504: _problem(504, "The job failed past its budget."),
    },
)
def get_job_result(job_id: str, request: Request) -> Response:
    """Exactly what the synchronous endpoint would have answered: the body once `done`, in the
    format the trajectory asked (`output.format`; CSV also when `Accept` prefers `text/csv`),
    the job's problem+json (with its own status) once `failed`."""
    store = _store(request)
    job = _job(store, job_id)
    if job.status == "done":
        result = store.result(job_id)
        if result is not None:
            return _answer(job, result, store.request(job_id), request.headers.get("accept"))
    if job.status == "failed" and job.error is not None:
        return Response(orjson.dumps(job.error), status_code=int(job.error.get("status", 500)), media_type=PROBLEM_JSON)
    if job.status in ("cancelled", "interrupted"):  # no answer will come: it ended without one
        route = "POST /v1/batches" if job.kind == "batch" else "POST /v1/jobs"
        raise JobNotDone(f"job {job_id} was {job.status} and has no answer; submit its request again ({route})")
    raise JobNotDone(f"job {job_id} is {job.status}; GET /v1/jobs/{job_id} shows its progress")


def _answer(job: Job, result: bytes, request_json: str | None, accept: str | None) -> Response:
    """The stored answer (JSON) in the format the job asked or, when it asked the default, the
    one its Accept header prefers, as ``POST /v1/trajectories`` chooses: CSV is written from
    the stored samples."""
    if job.kind == "trajectory" and request_json is not None:
        requested = TrajectoryRequest.model_validate_json(request_json).output.format  # the defaults of what was given
        if chosen_format(requested, accept) == "csv":
            body = orjson.loads(result)
            if "samples" in body:
                return Response(csv_bytes(body), media_type=CSV_MEDIA_TYPE)
    return Response(result, media_type="application/json")


@router.delete(
    "/{job_id}",
    summary="Cancel a job, or delete an ended one",
    response_model=JobPublic,
    responses={
        204: {"description": "The job had ended (done, failed, cancelled, interrupted): it and its answer are deleted."},
        404: _problem(404, "No job has that id."),
    },
)
def cancel_job(job_id: str, request: Request) -> Response:
    """Cancel a queued or running job (200, the job cancelled): a queued one never runs; a
    running one stops computing at once. A job that has ended (done, failed, cancelled,
    interrupted) is deleted with its stored answer (204); GET answers 404 for it afterwards."""
    store = _store(request)
    if _job(store, job_id).status in ("queued", "running"):
        try:
            cancelled = request.app.state.jobs.cancel(job_id)
        except JobEnded:
            cancelled = None  # it ended meanwhile: deleted below
        if cancelled is not None:
            return _job_response(cancelled)
    if not store.delete(job_id):
        return _job_response(_job(store, job_id))  # pruned meanwhile (404), or cancelled by another request
    return Response(status_code=204)
