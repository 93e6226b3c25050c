"""Background jobs: the SQLite job store (``store``), what a job computes in its worker process
(``work``) and the runner that claims, runs, cancels and records them (``runner``)."""

from __future__ import annotations

from toptraj.service.jobs.runner import JobRunner
from toptraj.service.jobs.store import JobStore
from toptraj.service.jobs.work import WorkerSetup

#: Modules the fork server imports for the job workers (``toptraj.planners.execution.isolated.PRELOAD`` has the
#: solver stacks), so that a job's process neither imports the web stack (1 to 2 s) nor loads
#: the compiled kernels (0.5 s) again.
JOB_MODULES = ("toptraj.service.jobs.preload",)

__all__ = ["JOB_MODULES", "JobRunner", "JobStore", "WorkerSetup", "job_answer_bytes", "job_runner"]


def job_answer_bytes(settings) -> int:
    """The largest answer a job keeps, in bytes: the largest body served, within half the job
    store (``max_job_store_bytes``), so that the newest job's answer always fits in the store
    (a larger one would be pruned as soon as it was written, the job gone without a word); a
    larger answer fails the job with a 422 naming the ``output.dt`` that fits."""
    return min(settings.max_response_bytes, settings.max_job_store_bytes // 2)


def job_runner(settings) -> JobRunner:
    """The job runner of a service with ``settings`` (``toptraj.service.settings.Settings``), on the
    job store in its data directory."""
    store = JobStore(settings.data_dir, settings.max_jobs, settings.job_max_age_s, settings.max_job_store_bytes)
    setup = WorkerSetup(
        data_dir=str(settings.data_dir),
        max_uploads=settings.max_uploads,
        max_upload_bytes=settings.max_upload_bytes,
        upload_cache_size=settings.upload_cache_size,
        max_response_bytes=job_answer_bytes(settings),
        ray_address=settings.ray_address,
        search_memory_bytes=settings.search_memory_bytes,
        job_budget_s=settings.job_budget_s,
        job_max_budget_s=settings.job_max_budget_s,
    )
    return JobRunner(store, settings.job_workers, setup)
