"""What the job store (``toptraj.service.jobs.store``) holds and answers: a job's record, a job a runner
has claimed, the owner string that names a job's runner (host|pid|token) and whether that
runner is known to be gone, and the store's errors (each with its HTTP status).
"""

from __future__ import annotations

import json
import os
import socket
from dataclasses import dataclass

from toptraj.robots.errors import ToptrajError


class JobStoreUnavailable(ToptrajError):
    """SQLite or the file system failed: the data directory cannot be used for jobs."""

    status = 503
    title = "Job store unavailable"


class JobQueueFull(ToptrajError):
    """As many jobs wait as the service queues; a later submission may find room."""

    status = 503
    title = "Job queue full"

    def __init__(self, detail: str, retry_after: int = 10):
        super().__init__(detail)
        self.retry_after = retry_after


class JobEnded(ToptrajError):
    """The job has ended already; there is nothing to cancel."""

    status = 409
    title = "Job already ended"


@dataclass(frozen=True)
class Job:
    """One job as stored, without its result.

    Attributes:
        id: 32 hex digits.
        kind: What it computes: "trajectory" or "compare".
        status: One of ``toptraj.service.jobs.store.STATUSES``.
        fraction: Progress in [0, 1].
        stage: What is under way, e.g. "collocation: guess 3 of 15".
        budget_s: Computing time allowed once running, s.
        created, started, finished: Unix times (s), ``None`` until they happen.
        error: The problem+json object of a failed or interrupted job.
        seq: Order of submission.
    """

    id: str
    kind: str
    status: str
    fraction: float
    stage: str
    budget_s: float
    created: float
    started: float | None
    finished: float | None
    error: dict | None
    seq: int

    @classmethod
    def from_row(cls, row) -> Job:
        job_id, kind, status, fraction, stage, budget_s, created, started, finished, error, seq = row
        problem = None if error is None else json.loads(error)
        return cls(job_id, kind, status, fraction, stage, budget_s, created, started, finished, problem, seq)


@dataclass(frozen=True)
class ClaimedJob:
    """A job a runner has claimed: what it needs to compute it."""

    id: str
    kind: str
    request: str
    budget_s: float


def owner_is_gone(owner: str | None, live_tokens: set[str]) -> bool:
    """Whether the process named by ``owner`` (host|pid|token) is known to be gone: on this
    host, its process does not exist, or it is this very process and the token is not one of
    its live runners. Owners on other hosts are judged by their heartbeat only."""
    try:
        host, pid_text, token = (owner or "").split("|")
        pid = int(pid_text)
    except ValueError:
        return True
    if host != socket.gethostname():
        return False
    if pid == os.getpid():
        return token not in live_tokens
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:  # a process of another user holds the pid: not ours any more
        return True
    return False


def owner_name(token: str) -> str:
    """The owner string of a runner of this process with ``token``: host|pid|token."""
    return f"{socket.gethostname()}|{os.getpid()}|{token}"
