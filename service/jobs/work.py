"""What a job computes, in its worker process: a job is a kind and a request (JSON), and
``compute`` turns it into the JSON body the synchronous endpoint would answer.

A kind is a function ``(request JSON, deadline, setup) -> bytes`` in ``KINDS``; it reports its
progress through ``deadline.progress`` and never knows it runs as a job. A kind holding many
requests (a batch) is one more entry: it loops over its requests (or hands them to other
workers) and reports "request k of n".

``compute`` runs in a process forked from the fork server (``planners.isolated``), which shares
no module state with the server: the upload store and the body cap reach it in ``WorkerSetup``.
"""

from __future__ import annotations

from dataclasses import dataclass

import robots
from planners import Deadline
from planners.deadline import Progress
from planners.errors import InvalidRequest
from service.planning import compare_request, encode_json, plan_request, render
from service.schemas.trajectories import CompareRequest, TrajectoryRequest


@dataclass(frozen=True)
class WorkerSetup:
    """The server's settings a worker process needs: where uploads live (and their caps), and
    the largest answer body served, in bytes."""

    data_dir: str
    max_uploads: int
    max_upload_bytes: int
    upload_cache_size: int
    max_response_bytes: int


def _trajectory(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    body = TrajectoryRequest.model_validate_json(request)
    return render(plan_request(body, deadline, setup.max_response_bytes), body)[0]


def _compare(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    return encode_json(compare_request(CompareRequest.model_validate_json(request), deadline))


#: Each kind of job and the function computing it.
KINDS = {"trajectory": _trajectory, "compare": _compare}


def compute(kind: str, request: str, budget_s: float, setup: WorkerSetup, progress: Progress) -> bytes:
    """The JSON body answering ``request`` of ``kind``, computed within ``budget_s`` seconds,
    reporting to ``progress(fraction, stage)``.

    Raises:
        ToptrajError: what the synchronous endpoint would answer as a problem (e.g.
            ``InfeasiblePath``, ``BudgetExceeded``).
    """
    if kind not in KINDS:
        raise InvalidRequest(f"unknown job kind {kind!r}; known: {', '.join(KINDS)}")
    robots.configure_uploads(
        setup.data_dir,
        max_uploads=setup.max_uploads,
        max_bytes=setup.max_upload_bytes,
        cache_size=setup.upload_cache_size,
    )
    progress(0.0, "starting")
    return KINDS[kind](request, Deadline(budget_s, progress=progress), setup)
