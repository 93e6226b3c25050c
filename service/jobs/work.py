"""What a job computes, in its worker process: a job is a kind and a request (JSON), and
``compute`` turns it into the JSON body the synchronous endpoint would answer.

A kind is a function ``(request JSON, deadline, setup) -> bytes`` in ``KINDS``; it reports its
progress through ``deadline.progress`` and never knows it runs as a job. A kind holding many
requests (a batch) is one more entry: it loops over its requests (or hands them to other
workers) and reports "request k of n".

``compute`` runs in a process forked from the fork server (``toptraj.planners.execution.isolated``), which shares
no module state with the server: the upload store and the body cap reach it in ``WorkerSetup``.
"""

from __future__ import annotations

from dataclasses import dataclass

import orjson

from toptraj import robots
from toptraj.planners import Deadline
from toptraj.planners.execution.deadline import Progress
from toptraj.planners.execution.memory import DEFAULT_SEARCH_MEMORY
from toptraj.service.budget_advice import advised_line, as_job, job_kind
from toptraj.service.jobs.answer_room import AnswerRoom, kept_results
from toptraj.service.planning import compare_request, encode_json, plan_request, render
from toptraj.service.problems import RequestRefused
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest


@dataclass(frozen=True)
class WorkerSetup:
    """The server's settings a worker process needs: where uploads live (and their caps), the
    largest answer body served and the memory cap of a search, in bytes; a job's default and
    largest budgets, in s (for the advice of a batch line past its budget)."""

    data_dir: str
    max_uploads: int
    max_upload_bytes: int
    upload_cache_size: int
    max_response_bytes: int
    ray_address: str | None = None
    search_memory_bytes: int = DEFAULT_SEARCH_MEMORY
    job_budget_s: float = 300.0
    job_max_budget_s: float = 3_600.0


def _trajectory(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    """The answer as JSON, in the format asked; a job asking CSV keeps its samples as JSON (a
    job's answer is part of ``GET /v1/jobs/{id}``), planned as CSV is (on whole periods), and
    ``GET /v1/jobs/{id}/result`` writes them as CSV."""
    body = TrajectoryRequest.model_validate_json(request)
    result = plan_request(body, deadline, setup.max_response_bytes, search_memory_bytes=setup.search_memory_bytes)
    if body.output.format == "csv":
        body = body.model_copy(update={"output": body.output.model_copy(update={"format": "samples"})})
    return render(result, body)[0]


def _compare(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    return encode_json(compare_request(CompareRequest.model_validate_json(request), deadline))


def _batch(request: str, deadline: Deadline, setup: WorkerSetup) -> bytes:
    """Every request of a batch (``POST /v1/batches``) answered as its own endpoint would: a
    line's failure, whatever it is, is that line's result (``batches.work.answer``), and a line
    the job's budget did not reach is a 504 of its own, so the job ends with every answer it
    has; the answers are kept within the job's answer cap (``answer_room``: once they fill it,
    the requests left are not planned). Here one after another, or on the Ray cluster at
    ``setup.ray_address`` (``TOPTRAJ_RAY_ADDRESS``)."""
    items = orjson.loads(request)["requests"]
    texts = [orjson.dumps(item).decode() for item in items]
    room = AnswerRoom(setup.max_response_bytes, len(texts))
    answers = _on_ray(texts, setup, deadline, room) if setup.ray_address else _here(texts, deadline, room, setup)
    return kept_results(answers)


def _line_advised(status: int, body: bytes, text: str, setup: WorkerSetup) -> bytes:
    """A line's answer past its budget (504) ending with how to plan it alone, as a job."""
    if status != 504:
        return body
    advice = as_job(job_kind(text), BATCH_REQUEST_BUDGET_S, setup.job_budget_s, setup.job_max_budget_s)
    return advised_line(status, body, advice.replace("<this request>", "<this line's request>"))


def _not_reached(budget_s: float | None) -> tuple[int, bytes]:
    from toptraj.service.batches.lines import problem_body

    detail = f"the batch's time budget of {budget_s:g} s was spent before this request was planned; submit it again, or the batch with a larger budget_s"
    return 504, problem_body(504, "Time budget exceeded", detail)


def _line_budget(deadline: Deadline) -> float:
    """Seconds a line may take: its own budget, within what is left of the job's less a
    reserve (``batch_reserve_s``): a solver step that cannot check its deadline runs past it
    (about a second for a six-joint collocation), and a batch whose process outlives its
    budget is killed with every answer it holds, where a line past its own is that line's 504."""
    remaining = deadline.remaining()
    if remaining is None:
        return BATCH_REQUEST_BUDGET_S
    return min(BATCH_REQUEST_BUDGET_S, remaining - batch_reserve_s(deadline.budget_s))


def batch_reserve_s(budget_s: float | None) -> float:
    """Seconds of a batch job's budget kept from its lines: a quarter of it, at most
    ``BATCH_RESERVE_S``."""
    return 0.0 if budget_s is None else min(BATCH_RESERVE_S, 0.25 * budget_s)


def _here(texts: list[str], deadline: Deadline, room: AnswerRoom, setup: WorkerSetup) -> list[tuple[int, bytes]]:
    from toptraj.service.batches.work import answer

    answers = []
    for k, text in enumerate(texts):
        deadline.progress(k / len(texts), f"batch: request {k + 1} of {len(texts)}")
        budget = _line_budget(deadline)
        if room.full():
            answers.append(room.not_kept(k))
        elif budget > MIN_LINE_BUDGET_S:
            status, body = answer(text, budget, room.cap_bytes)
            answers.append(room.keep(k, status, _line_advised(status, body, text, setup)))
        else:
            answers.append(_not_reached(deadline.budget_s))
    return answers


def _on_ray(texts: list[str], setup: WorkerSetup, deadline: Deadline, room: AnswerRoom) -> list[tuple[int, bytes]]:
    import ray

    from toptraj.service.batches.ray_pool import check_reachable
    from toptraj.service.batches.runner import _uploads_named
    from toptraj.service.batches.work import answer_on_worker

    if not ray.is_initialized():
        if setup.ray_address not in ("local", "auto"):
            check_reachable(str(setup.ray_address), "TOPTRAJ_RAY_ADDRESS")  # Ray would retry it for minutes, the job's whole budget
        ray.init(address=None if setup.ray_address == "local" else setup.ray_address, log_to_driver=False, configure_logging=False)
    remote = ray.remote(num_cpus=1, scheduling_strategy="SPREAD")(answer_on_worker)
    uploads = ray.put(_uploads_named(texts))
    budget = _line_budget(deadline)
    pending = {remote.remote([(str(k), text)], uploads, budget, room.cap_bytes): k for k, text in enumerate(texts)}
    answers: list[tuple[int, bytes] | None] = [None] * len(texts)
    while pending and _line_budget(deadline) > 0.0 and not room.full():
        ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
        for ref in ready:
            k = pending.pop(ref)
            try:
                _, [(_, status, body)] = ray.get(ref)
                answers[k] = room.keep(k, status, _line_advised(status, body, texts[k], setup))
            except Exception as error:  # the task as a whole: its worker died
                answers[k] = (500, _worker_failed(error))
        done = len(texts) - len(pending)
        deadline.progress(done / len(texts), f"batch: {done} of {len(texts)} on Ray")
    for ref in pending:
        ray.cancel(ref, force=True)
    return [
        answer if answer is not None else room.not_kept(k) if room.full() else _not_reached(deadline.budget_s)
        for k, answer in enumerate(answers)
    ]


def _worker_failed(error: BaseException) -> bytes:
    from toptraj.service.batches.lines import problem_body

    return problem_body(500, "Worker failed", f"the worker planning this request failed ({type(error).__name__}); submit it again")


#: Each kind of job and the function computing it.
KINDS = {"trajectory": _trajectory, "compare": _compare, "batch": _batch}
#: Planning budget of one request of a batch, in s (as the synchronous endpoint's default).
BATCH_REQUEST_BUDGET_S = 20.0
#: Least time left of a batch job's budget in which another request is started, in s.
MIN_LINE_BUDGET_S = 0.05
#: Most seconds of a batch job's budget kept from its lines (``batch_reserve_s``).
BATCH_RESERVE_S = 5.0


def compute(kind: str, request: str, budget_s: float, setup: WorkerSetup, ends_at: float | None, progress: Progress) -> bytes:
    """The JSON body answering ``request`` of ``kind``, computed within ``budget_s`` seconds
    ending at ``ends_at`` (``time.monotonic()``, the same clock in every process: the job's
    runner counts them from the job's start, this process's start included; ``None``: from
    now), reporting to ``progress(fraction, stage)``.

    Raises:
        ToptrajError: what the synchronous endpoint would answer as a problem (e.g.
            ``InfeasiblePath``, ``BudgetExceeded``).
    """
    if kind not in KINDS:
        raise RequestRefused(f"unknown job kind {kind!r}; known: {', '.join(KINDS)}")
    robots.configure_uploads(
        setup.data_dir,
        max_uploads=setup.max_uploads,
        max_bytes=setup.max_upload_bytes,
        cache_size=setup.upload_cache_size,
    )
    progress(0.0, "starting")
    deadline = Deadline(budget_s, progress=progress) if ends_at is None else Deadline.ending_at(ends_at, budget_s, progress)
    return KINDS[kind](request, deadline, setup)
