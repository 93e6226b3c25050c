"""``JobCalls``: background jobs and batches (``/v1/jobs``, ``/v1/batches``): submit, follow
with a progress callback, read the answer, cancel. Part of ``client.Client``."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

from toptraj.client.errors import ProblemError
from toptraj.client.resources import BatchItem, Job, JobPage, answer_of
from toptraj.client.results import Comparison, CsvTrajectory, Trajectory
from toptraj.client.transport import CSV, Transport

#: ``progress(fraction, stage)``: called while a job is followed, each time its progress changes;
#: ``fraction`` in [0, 1] never goes back, ``stage`` says what is under way.
Progress = Callable[[float, str], None]


def _id(job: Job | str) -> str:
    return job.id if isinstance(job, Job) else job


class JobCalls(Transport):
    """The job and batch calls of ``client.Client``."""

    def submit(self, request: dict, budget_s: float | None = None) -> Job:
        """``POST /v1/jobs``: compute a trajectory or a comparison in the background.

        Args:
            request: The body of ``POST /v1/trajectories`` (e.g. from ``trajectory_request``)
                or, naming ``methods``, of ``POST /v1/trajectories/compare``.
            budget_s: Computing time allowed once the job runs (s); the server's default
                (300 s) otherwise, at most its maximum (3,600 s by default).

        Returns:
            The job, ``queued``; follow it with ``wait``.

        Raises:
            ProblemError: 404 unknown robot, 422 malformed request or, for a trajectory,
                one the service refuses before planning (as ``plan`` would: a waypoint of
                the wrong length, a free path's end too close to an obstacle, a grid over the
                memory cap), 503 the queue is full.
        """
        kind = "compare" if "methods" in request else "trajectory"
        body: dict[str, Any] = {kind: request}
        if budget_s is not None:
            body["budget_s"] = budget_s
        return Job.from_body(self._call("POST", "/v1/jobs", body))

    def submit_batch(self, requests: Sequence[dict], budget_s: float | None = None) -> Job:
        """``POST /v1/batches``: many requests (trajectory or compare bodies, at most 200) as one
        job; each request is checked at once (422 naming the first bad one).

        Returns:
            The job, ``queued``; ``wait`` for it, then ``batch_results``.
        """
        body: dict[str, Any] = {"requests": list(requests)}
        if budget_s is not None:
            body["budget_s"] = budget_s
        return Job.from_body(self._call("POST", "/v1/batches", body))

    def job(self, job: Job | str) -> Job:
        """``GET /v1/jobs/{id}``: a job's status and progress, with its answer once done
        (``result``) or its problem once failed (``error``).

        Raises:
            ProblemError: 404 when no job has that id (never existed, or ended and deleted).
        """
        return Job.from_body(self._call("GET", f"/v1/jobs/{_id(job)}"))

    def jobs(self, limit: int = 20, cursor: str | None = None, status: str | None = None) -> JobPage:
        """``GET /v1/jobs``: one page of the jobs the server keeps, newest first, without their
        answers; pass the page's ``next_cursor`` as ``cursor`` for the next one.

        Args:
            limit: Jobs per page, 1 to 100.
            cursor: ``next_cursor`` of the previous page.
            status: Only jobs with this status (``queued``, ``running``, ``done``, ...).
        """
        params: dict[str, Any] = {"limit": limit}
        if cursor is not None:
            params["cursor"] = cursor
        if status is not None:
            params["status"] = status
        body = self._call("GET", "/v1/jobs", params=params)
        return JobPage([Job.from_body(job) for job in body["jobs"]], body["next_cursor"])

    def job_result(
        self, job: Job | str, format: str | None = None
    ) -> Trajectory | CsvTrajectory | list[Comparison] | list[BatchItem]:
        """``GET /v1/jobs/{id}/result``: a done job's answer alone, as the synchronous endpoint
        would have answered it.

        Args:
            job: The job or its id.
            format: ``"csv"`` to ask for the trajectory as CSV (``Accept: text/csv``); a server
                that keeps job answers as JSON only answers JSON, read as such. Otherwise the
                answer comes in the request's own ``output.format``.

        Returns:
            A ``Trajectory`` (or ``CsvTrajectory``), a list of ``Comparison``, or for a batch a
            list of ``BatchItem``.

        Raises:
            ProblemError: 409 when the job has not ended or ended without an answer
                (cancelled, interrupted); a failed job's own problem (e.g. 422, 504).
        """
        headers = {"accept": f"{CSV}, application/json;q=0.5"} if format == "csv" else None
        answer = self._answer(self.request("GET", f"/v1/jobs/{_id(job)}/result", headers=headers))
        return answer if isinstance(answer, CsvTrajectory) else answer_of(answer)

    def batch_results(self, job: Job | str) -> list[BatchItem]:
        """A done batch's answers, in the order of its requests (``GET /v1/jobs/{id}/result``):
        each ``BatchItem`` holds its request's ``result`` or ``error``."""
        answer = self.job_result(job)
        if not isinstance(answer, list) or not all(isinstance(item, BatchItem) for item in answer):
            raise TypeError(f"job {_id(job)} is not a batch")
        return answer  # type: ignore[return-value]

    def cancel_job(self, job: Job | str) -> Job | None:
        """``DELETE /v1/jobs/{id}``: cancel a queued or running job (its worker process is
        stopped), or delete an ended one with its answer.

        Returns:
            The job, ``cancelled``, if it was queued or running; None if it had ended and is
            now deleted.

        Raises:
            ProblemError: 404 when no job has that id.
        """
        response = self.request("DELETE", f"/v1/jobs/{_id(job)}")
        return Job.from_body(response.json()) if response.status_code == 200 else None

    def wait(self, job: Job | str, progress: Progress | None = None, poll_s: float = 0.5, timeout_s: float = 3600.0) -> Job:
        """Follow a job until it ends, calling ``progress(fraction, stage)`` each time its
        progress changes.

        Args:
            job: The job or its id.
            progress: Called with the job's fraction (in [0, 1], never going back) and stage
                whenever they change, last with ``(1.0, "done")`` when it is done.
            poll_s: Seconds between two looks at the job.
            timeout_s: Seconds to follow it at most; the job runs on after.

        Returns:
            The job, ``done``, its answer in ``result``.

        Raises:
            ProblemError: The job failed (its problem, e.g. 422 or 504 past its budget), or
                ended without an answer (409: cancelled, interrupted).
            TimeoutError: The job did not end within ``timeout_s``.
        """
        deadline = time.monotonic() + timeout_s
        seen: tuple[float, str] | None = None
        while True:
            state = self.job(job)
            if progress is not None and (state.fraction, state.stage) != seen:
                seen = (state.fraction, state.stage)
                progress(*seen)
            if state.status == "done":
                return state
            if state.ended:
                if state.error is not None:
                    raise state.error
                self.job_result(state)  # the service's 409: the job has no answer
                raise ProblemError({"status": 409, "title": "Job has no answer", "detail": f"job {state.id} is {state.status}"})
            if time.monotonic() + poll_s > deadline:
                raise TimeoutError(f"job {state.id} is still {state.status} after {timeout_s:g} s ({state.stage})")
            time.sleep(poll_s)

    def plan_in_background(
        self,
        request: dict,
        budget_s: float | None = None,
        poll_s: float = 0.5,
        timeout_s: float = 3600.0,
        progress: Progress | None = None,
    ) -> Trajectory:
        """A long request (a free path, a search) as a job: submitted, followed and returned as
        the synchronous endpoint would have answered it; cancelled if it outlasts ``timeout_s``.

        Raises:
            ProblemError: As ``plan`` would (the job's problem), or 409 if it was cancelled.
            TimeoutError: It did not end within ``timeout_s`` (it is then cancelled).
        """
        job = self.submit(request, budget_s)
        try:
            done = self.wait(job, progress, poll_s, timeout_s)
        except TimeoutError:
            self.cancel_job(job)
            raise
        if not isinstance(done.result, Trajectory):
            raise TypeError(f"job {job.id} answered no trajectory: the request names methods (a comparison)")
        return done.result

    def run_batch(
        self,
        requests: Sequence[dict],
        budget_s: float | None = None,
        progress: Progress | None = None,
        poll_s: float = 0.5,
        timeout_s: float = 3600.0,
    ) -> list[BatchItem]:
        """``submit_batch``, ``wait`` and ``batch_results`` in one call: every request's answer
        or problem, in order (one request's failure is its item's ``error``, not raised)."""
        job = self.submit_batch(requests, budget_s)
        done = self.wait(job, progress, poll_s, timeout_s)
        return done.result if isinstance(done.result, list) else self.batch_results(job)  # type: ignore[return-value]
