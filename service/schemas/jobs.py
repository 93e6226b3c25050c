"""Schemas of the job resource (``/v1/jobs``): a trajectory or a comparison computed in the
background, with its progress, then its answer or its error."""

from __future__ import annotations

from datetime import datetime
from typing import Literal

from pydantic import BaseModel, Field, model_validator

from toptraj.service.schemas.answers import CompareResponse, TrajectoryResponse
from toptraj.service.schemas.common import Problem, Schema
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest

JobKind = Literal["trajectory", "compare", "batch"]
JobStatus = Literal["queued", "running", "done", "failed", "cancelled", "interrupted"]


class JobCreate(Schema):
    """A job: exactly one of ``trajectory`` (the body of ``POST /v1/trajectories``) or
    ``compare`` (the body of ``POST /v1/trajectories/compare``); the key names the kind."""

    model_config = {
        "json_schema_extra": {"oneOf": [{"required": ["trajectory"]}, {"required": ["compare"]}]},
    }

    # Typed without None: a key given must hold a request (null is refused); absent, it is None.
    trajectory: TrajectoryRequest = Field(default=None, description="The body of `POST /v1/trajectories`.")  # type: ignore[assignment]
    compare: CompareRequest = Field(default=None, description="The body of `POST /v1/trajectories/compare`.")  # type: ignore[assignment]
    budget_s: float | None = Field(
        default=None,
        ge=0.1,
        description="Computing time allowed once the job runs, in s (waiting in the queue does not count). "
        "Default 300 s (`TOPTRAJ_JOB_BUDGET_S`); at most the server's maximum, 3,600 s by default "
        "(`TOPTRAJ_JOB_MAX_BUDGET_S`; more gets 422 naming it).",
    )

    @model_validator(mode="before")
    @classmethod
    def _not_both(cls, data: object) -> object:
        """Both kinds given: refused as such before either is read (else a trajectory body
        under ``compare`` would be reported as a compare missing its ``methods``)."""
        if isinstance(data, dict) and "trajectory" in data and "compare" in data:
            raise ValueError(
                "give exactly one of `trajectory` (a POST /v1/trajectories body) or `compare` "
                "(a POST /v1/trajectories/compare body), not both: a job computes one of them; submit two jobs for both"
            )
        return data

    @model_validator(mode="after")
    def _one_kind(self) -> JobCreate:
        given = [name for name in ("trajectory", "compare") if name in self.model_fields_set]
        if len(given) != 1:
            raise ValueError(
                "give exactly one of `trajectory` (a POST /v1/trajectories body) or `compare` "
                f"(a POST /v1/trajectories/compare body); got {' and '.join(given) or 'neither'}"
            )
        return self

    @property
    def kind(self) -> JobKind:
        return "trajectory" if self.trajectory is not None else "compare"

    @property
    def request(self) -> TrajectoryRequest | CompareRequest:
        return self.trajectory if self.trajectory is not None else self.compare


class JobProgress(BaseModel):
    """How far the job is: a fraction of the work and what is under way."""

    fraction: float = Field(ge=0.0, le=1.0, description="0 when queued, 1 when done.")
    stage: str = Field(description='e.g. "collocation: guess 3 of 15", "limit check, round 1", "sampling".')


class JobSummary(BaseModel):
    """A job without its answer (``GET /v1/jobs/{id}`` carries the answer)."""

    id: str = Field(description="32 hex digits.")
    kind: JobKind = Field(description="`trajectory`, `compare` or `batch`: what the job computes.")
    status: JobStatus = Field(
        description="`queued` (waits for a job worker), `running`, `done` (see `result`), `failed` (see "
        "`error`), `cancelled` (DELETE), `interrupted` (the server stopped while it ran; submit it again)."
    )
    progress: JobProgress = Field(description="How far the job is.")
    budget_s: float = Field(description="Computing time allowed once running, s.")
    created_at: datetime = Field(description="When the job was submitted (UTC).")
    started_at: datetime | None = Field(default=None, description="When it started running (UTC); null while queued.")
    finished_at: datetime | None = Field(default=None, description="When it ended (UTC); null until then.")
    error: Problem | None = Field(
        default=None,
        description="When failed or interrupted: the problem+json object the synchronous endpoint would "
        "answer (status, title, detail, and `s`, `joint`, `limit` where a limit cannot be met; 504 "
        "past the budget).",
    )


#: Most requests of one batch (each answer may be large: a trajectory body of a 6-joint arm
#: at dt = 0.01 s is about 100 kB, and a job's answer is held by the job store).
MAX_BATCH_REQUESTS = 200


class BatchCreate(Schema):
    """Many requests in one job: each the body of `POST /v1/trajectories` or, naming `methods`,
    of `POST /v1/trajectories/compare`."""

    requests: list[dict] = Field(
        min_length=1,
        max_length=MAX_BATCH_REQUESTS,
        description="The requests, each checked now against its schema (a 422 names the first bad one).",
    )
    budget_s: float | None = Field(
        default=None, ge=0.1, description="Computing time of the whole batch once it runs, in s (as a job's). Each request gets at most "
        "20 s of it (the synchronous budget), within what is left; a request that needs more is planned alone as a job "
        "(`POST /v1/jobs`), as its 504 says."
    )


class BatchResult(BaseModel):
    """One request's answer in a batch."""

    line: int = Field(description="The request's position in `requests`, from 1.")
    status: int = Field(description="The HTTP status its own endpoint would answer.")
    body: dict = Field(description="Its answer, or its problem+json.")


class BatchResponse(BaseModel):
    """A batch's answers, in the order of its requests."""

    results: list[BatchResult] = Field(description="One per request, errors included.")


class JobPublic(JobSummary):
    """A job, with its answer once done."""

    result: TrajectoryResponse | CompareResponse | BatchResponse | None = Field(
        default=None,
        description="When done: the very body the synchronous endpoint answers (a batch: every answer); JSON "
        "here, the samples of a trajectory that asked `csv` included: `GET /v1/jobs/{id}/result` serves them as CSV.",
    )


class JobList(BaseModel):
    """A page of jobs, newest first."""

    jobs: list[JobSummary] = Field(description="The page's jobs, newest first, without their answers.")
    next_cursor: str | None = Field(description="Pass as `cursor` for the next (older) page; null on the last page.")
