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

import orjson

import robots
from planners import Deadline
from planners.deadline import Progress
from planners.errors import InvalidRequest
from planners.search.graph import DEFAULT_SEARCH_MEMORY
from service.planning import compare_request, encode_json, plan_request, render
from service.schemas.trajectories import CompareRequest, TrajectoryRequest


@dataclass(frozen=True)
class WorkerSetup:
    """The server's settings a worker process needs: where uploads live (and their caps), the
    largest answer body served and the memory cap of a search, in bytes."""

    data_dir: str
    max_uploads: int
    max_upload_bytes: int
    upload_cache_size: int
    max_response_bytes: int
    ray_address: str | None = None
    search_memory_bytes: int = DEFAULT_SEARCH_MEMORY


def _trajectory(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    body = TrajectoryRequest.model_validate_json(request)
    return render(plan_request(body, deadline, setup.max_response_bytes, search_memory_bytes=setup.search_memory_bytes), body)[0]


def _compare(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    return encode_json(compare_request(CompareRequest.model_validate_json(request), deadline))


def _batch(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    """Every request of a batch (``POST /v1/batches``) answered as its own endpoint would,
    errors included, within the job's budget: here one after another, or on the Ray cluster at
    ``setup.ray_address`` (``TOPTRAJ_RAY_ADDRESS``)."""
    from service.batches.work import answer_chunk

    items = orjson.loads(request)["requests"]
    lines = [(str(k), orjson.dumps(item).decode(), k + 1) for k, item in enumerate(items)]
    budget = min(BATCH_REQUEST_BUDGET_S, deadline.remaining() or BATCH_REQUEST_BUDGET_S)
    if setup.ray_address:
        return encode_json({"results": _on_ray(lines, setup, deadline)})
    results = []
    for k, line in enumerate(lines):
        deadline.check()
        deadline.progress(k / len(lines), f"batch: request {k + 1} of {len(lines)}")
        results.extend(answer_chunk([line], {}, min(budget, deadline.remaining() or budget)))
    return encode_json({"results": [_without_key(row) for row in results]})


def _without_key(line: bytes) -> dict:
    row = orjson.loads(line)
    del row["key"]
    return row


def _on_ray(lines, setup: WorkerSetup, deadline: Deadline) -> list[dict]:
    import ray

    from service.batches.runner import _uploads_named
    from service.batches.work import answer_chunk

    if not ray.is_initialized():
        ray.init(address=None if setup.ray_address == "local" else setup.ray_address, log_to_driver=False, configure_logging=False)
    remote = ray.remote(num_cpus=1)(answer_chunk)
    uploads = ray.put(_uploads_named([text for _, text, _ in lines]))
    pending = [remote.remote([line], uploads, BATCH_REQUEST_BUDGET_S) for line in lines]
    results = []
    while pending:
        deadline.check()
        ready, pending = ray.wait(pending, num_returns=1, timeout=0.5)
        for ref in ready:
            results.extend(ray.get(ref))
        deadline.progress(len(results) / len(lines), f"batch: {len(results)} of {len(lines)} on Ray")
    return sorted((_without_key(row) for row in results), key=lambda row: row["line"])


#: Each kind of job and the function computing it.
KINDS = {"trajectory": _trajectory, "compare": _compare, "batch": _batch}
#: Planning budget of one request of a batch, in s (as the synchronous endpoint's default).
BATCH_REQUEST_BUDGET_S = 20.0


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
