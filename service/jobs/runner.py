"""The job runner of one server process: it claims queued jobs from the store, computes each in
a worker process of its own, writes progress and the outcome back, and stops the work of a
cancelled job.

* At most ``workers`` jobs run at once in all the processes sharing the store (the claim
  counts the running jobs in the same transaction); the rest wait, queued.
* Each job runs ``work.compute`` through ``toptraj.planners.execution.isolated.run_isolated``: a process forked
  from the fork server, killed when the job is cancelled, when its budget (plus ``GRACE_S``) is
  spent, or when this server stops. The job thread of this process only waits on its pipe.
* Progress reports come over that pipe and are written to the store at most every
  ``PROGRESS_WRITE_S`` seconds per job (the last one is never lost: the dispatcher flushes it).
* A dispatcher thread wakes on a submission in this process, or every ``POLL_S`` seconds (a
  submission to another process, a ``DELETE`` in another process); it writes a heartbeat for
  the running jobs every ``HEARTBEAT_S`` seconds and takes over as interrupted the running jobs
  of processes that are gone (``JobStore.interrupt_orphans``), at start and every
  ``SWEEP_S`` seconds.
* ``close`` (the server stops) kills the local work and marks those jobs interrupted; queued
  jobs stay queued for the next start, or for another process on the same store.
"""

from __future__ import annotations

import logging
import threading
import time
import uuid
from dataclasses import dataclass, field

from toptraj.planners import Deadline
from toptraj.planners.errors import BudgetExceeded, ShareSpent
from toptraj.planners.execution.isolated import run_isolated
from toptraj.robots.errors import ToptrajError
from toptraj.service.budget_advice import larger_job_budget
from toptraj.service.jobs import work
from toptraj.service.jobs.records import ClaimedJob, Job, JobStoreUnavailable, owner_name
from toptraj.service.jobs.store import JobStore
from toptraj.service.problems import detail, status_of, title_of

logger = logging.getLogger("toptraj.jobs")

#: Seconds between two looks at the store for work or cancellations, when nothing runs here.
POLL_IDLE_S = 0.5
#: ... and while jobs run here (a DELETE in another process stops the work within this).
POLL_S = 0.2
#: Seconds between two heartbeats of the running jobs.
HEARTBEAT_S = 2.0
#: Seconds between two searches for running jobs of processes that are gone.
SWEEP_S = 5.0
#: Shortest interval between two progress writes of one job, in s (at most 5 writes/s).
PROGRESS_WRITE_S = 0.2
#: Seconds past its budget after which a job's worker process is killed (its own deadline
#: checks end it at the budget; a solver step that cannot check one is cut here).
GRACE_S = 0.5

#: Tokens of the runners alive in this process (a running job whose owner names this process
#: and another token belongs to a runner that is gone).
_LIVE_TOKENS: set[str] = set()
_LIVE_LOCK = threading.Lock()

INTERRUPTED = {
    "type": "about:blank",
    "title": "Job interrupted",
    "status": 503,
    "detail": "the server process running this job stopped before the job ended; submit it again",
}


def problem_of(error: BaseException) -> dict:
    """The problem+json object of a job's error: a ``ToptrajError`` with its status, title,
    detail and the ``s``, ``joint`` and ``limit`` facts it carries; anything else as a 500."""
    if isinstance(error, ToptrajError):
        body = {"type": "about:blank", "title": title_of(error), "status": status_of(error), "detail": detail(error)}
        for key in ("s", "joint", "limit"):
            if getattr(error, key, None) is not None:
                body[key] = getattr(error, key)
        return body
    return {
        "type": "about:blank",
        "title": "Internal error",
        "status": 500,
        "detail": f"an unexpected {type(error).__name__} occurred; it has been logged",
    }


class _Progress:
    """The progress of one running job: the latest report, written to the store at most every
    ``PROGRESS_WRITE_S`` seconds; the fraction never goes back."""

    def __init__(self, store: JobStore, job_id: str, owner: str):
        self._store, self._job_id, self._owner = store, job_id, owner
        self._lock = threading.Lock()
        self._fraction = 0.0
        self._pending: tuple[float, str] | None = None
        self._written = 0.0

    def report(self, fraction: float, stage: str) -> None:
        with self._lock:
            self._fraction = max(self._fraction, min(float(fraction), 1.0))
            self._pending = (self._fraction, stage)
        self.flush()

    def flush(self) -> None:
        with self._lock:
            if self._pending is None or time.monotonic() - self._written < PROGRESS_WRITE_S:
                return
            (fraction, stage), self._pending = self._pending, None
            self._written = time.monotonic()
            try:
                self._store.report(self._job_id, self._owner, fraction, stage)
            except JobStoreUnavailable as error:
                logger.warning("progress of job %s not written: %s", self._job_id, error.detail)


@dataclass
class _Running:
    """A job running in this process: its deadline (cancelled to stop the work) and progress."""

    job: ClaimedJob
    deadline: Deadline
    progress: _Progress
    thread: threading.Thread | None = None
    stopped: bool = field(default=False)

    def stop(self) -> None:
        self.stopped = True
        self.deadline.cancel()

    @property
    def ends_at(self) -> float | None:
        """When the job's own budget ends (``time.monotonic()``): its deadline less the grace
        after which its process is killed."""
        end = self.deadline.end
        return None if end is None else end - GRACE_S


class JobRunner:
    """Runs the jobs of ``store``: at most ``workers`` at once over every process sharing it,
    each in a worker process computing ``compute(kind, request, budget_s, setup, ends_at, progress)``
    (``ends_at``: when the job's budget ends, ``time.monotonic()``, counted from its start here,
    the worker's start included).

    Args:
        store: The job store (shared by every server process on the data directory).
        workers: Most jobs running at once.
        setup: What the worker processes need of the settings.
        compute: The function a worker process runs (``work.compute``; module level, so that
            it reaches the worker by name).
    """

    def __init__(self, store: JobStore, workers: int, setup: work.WorkerSetup, compute=work.compute):
        self.store, self.workers, self.setup, self.compute = store, workers, setup, compute
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stopping = threading.Event()
        self._running: dict[str, _Running] = {}
        self._dispatcher: threading.Thread | None = None
        self.owner: str | None = None
        self._token: str | None = None

    # Life -------------------------------------------------------------------------------------
    def start(self) -> None:
        """Start the dispatcher (again after ``close``): first take over as interrupted the
        running jobs of processes that are gone, then run queued jobs. Idempotent."""
        with self._lock:
            if self._dispatcher is not None:
                return
            self._token = uuid.uuid4().hex[:12]
            self.owner = owner_name(self._token)
            with _LIVE_LOCK:
                _LIVE_TOKENS.add(self._token)
            self._stopping.clear()
            self._dispatcher = threading.Thread(target=self._dispatch, name="toptraj-jobs", daemon=True)
        self._sweep()
        self._dispatcher.start()

    def close(self, timeout_s: float = 10.0) -> None:
        """Stop: kill the work of the jobs running here and mark them interrupted. Queued jobs
        stay queued."""
        with self._lock:
            dispatcher, self._dispatcher = self._dispatcher, None
            if dispatcher is None:
                return
            self._stopping.set()
            running = list(self._running.values())
        self._wake.set()
        self.stop_running()
        dispatcher.join(timeout_s)
        for entry in running:
            if entry.thread is not None:
                entry.thread.join(timeout_s)
        if self.owner is None:  # never started
            return
        try:
            self.store.interrupt(self.owner, INTERRUPTED)
        except JobStoreUnavailable as error:
            logger.error("jobs of %s not marked interrupted: %s", self.owner, error.detail)
        with _LIVE_LOCK:
            _LIVE_TOKENS.discard(self._token)

    def stop_running(self) -> None:
        """Stop the work of the jobs running here (their outcome is left to ``close``, which
        marks them interrupted): a job waiting for its worker process to start ends once the
        fork server answers or is gone."""
        with self._lock:
            running = list(self._running.values())
        for entry in running:
            entry.stop()

    def wake(self) -> None:
        """Look for queued work now (a job was submitted)."""
        self.start()
        self._wake.set()

    def cancel(self, job_id: str) -> Job | None:
        """Cancel ``job_id`` (queued or running); its work stops at once when it runs in this
        process, within ``POLL_S`` when it runs in another. ``None`` when unknown.

        Raises:
            JobEnded: the job has ended already.
        """
        job = self.store.cancel(job_id)
        with self._lock:
            entry = self._running.get(job_id)
        if entry is not None and job is not None:
            entry.stop()
        return job

    def running_here(self) -> list[str]:
        """Ids of the jobs running in this process."""
        with self._lock:
            return list(self._running)

    # Dispatcher ---------------------------------------------------------------------------
    def _dispatch(self) -> None:
        next_heartbeat = next_sweep = time.monotonic()
        while not self._stopping.is_set():
            self._wake.wait(POLL_S if self.running_here() else POLL_IDLE_S)
            self._wake.clear()
            if self._stopping.is_set():
                return
            try:
                now = time.monotonic()
                self._watch(beat=now >= next_heartbeat)
                if now >= next_heartbeat:
                    next_heartbeat = now + HEARTBEAT_S
                if now >= next_sweep:
                    self._sweep()
                    next_sweep = now + SWEEP_S
                self._claim()
            except JobStoreUnavailable as error:
                logger.error("job store: %s", error.detail)
            except Exception:  # the dispatcher must go on
                logger.exception("job dispatcher")

    def _watch(self, beat: bool) -> None:
        """Flush progress; stop the work of local jobs that no longer run (cancelled in
        another process); write the heartbeat when ``beat``."""
        with self._lock:
            entries = list(self._running.values())
        if not entries:
            return
        for entry in entries:
            entry.progress.flush()
        ids = [entry.job.id for entry in entries]
        gone = self.store.heartbeat(self._me, ids) if beat else self._not_running(ids)
        for entry in entries:
            if entry.job.id in gone:
                entry.stop()

    @property
    def _me(self) -> str:
        """The owner name of this runner's jobs (``start`` sets it)."""
        assert self.owner is not None, "the job runner has not started"
        return self.owner

    def _not_running(self, ids: list[str]) -> set[str]:
        jobs = (self.store.get(job_id) for job_id in ids)
        return {job_id for job_id, job in zip(ids, jobs) if job is None or job.status != "running"}

    def _sweep(self) -> None:
        with _LIVE_LOCK:
            live = set(_LIVE_TOKENS)
        for job_id in self.store.interrupt_orphans(live, INTERRUPTED):
            logger.warning("job %s was running in a process that is gone: interrupted", job_id)

    def _claim(self) -> None:
        while len(self.running_here()) < self.workers and not self._stopping.is_set() and self.store.has_queued():
            job = self.store.claim(self._me, self.workers)
            if job is None:
                return
            progress = _Progress(self.store, job.id, self._me)
            entry = _Running(job, Deadline(job.budget_s + GRACE_S, progress=progress.report), progress)
            entry.thread = threading.Thread(target=self._run, args=(entry,), name=f"toptraj-job-{job.id[:8]}", daemon=True)
            with self._lock:
                self._running[job.id] = entry
            entry.thread.start()

    # One job ------------------------------------------------------------------------------
    def _run(self, entry: _Running) -> None:
        job = entry.job
        try:
            outcome = self._outcome(entry)
            if outcome is not None:
                entry.progress.flush()
                status, result, error = outcome
                self.store.finish(job.id, self._me, status, result, error)
        except JobStoreUnavailable as error:
            logger.error("job %s: outcome not written: %s", job.id, error.detail)
        finally:
            with self._lock:
                self._running.pop(job.id, None)
            self._wake.set()

    def _outcome(self, entry: _Running) -> tuple[str, bytes | None, dict | None] | None:
        """(status, result, error) of the job of ``entry``, ``None`` when it was stopped
        (cancelled, or the server stops: ``close`` marks it)."""
        job = entry.job
        try:
            result = run_isolated(
                self.compute, job.kind, job.request, job.budget_s, self.setup, entry.ends_at, deadline=entry.deadline, progress=True
            )
        except BudgetExceeded as error:
            if entry.stopped:
                return None
            advice = larger_job_budget(job.budget_s, self.setup.job_max_budget_s)
            if isinstance(error, ShareSpent):  # a method's share of the budget, not the whole of it
                return "failed", None, problem_of(ShareSpent(f"{error.detail}; {advice}"))
            return "failed", None, problem_of(BudgetExceeded(f"the job exceeded its time budget of {job.budget_s:g} s; {advice}"))
        except Exception as error:
            if entry.stopped:  # its process killed, or its fork server gone: not its failure
                return None
            if isinstance(error, ToptrajError):
                return "failed", None, problem_of(error)
            logger.error("job %s failed unexpectedly", job.id, exc_info=error)
            return "failed", None, problem_of(error)
        if len(result) > self.setup.max_response_bytes:
            return "failed", None, {
                "type": "about:blank",
                "title": "Answer too large",
                "status": 422,
                "detail": f"the answer has {len(result)} bytes; at most {self.setup.max_response_bytes} are kept",
            }
        return "done", result, None
