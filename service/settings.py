"""Service settings, read from ``TOPTRAJ_*`` environment variables."""

from __future__ import annotations

import os
from pathlib import Path

from pydantic import Field, model_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

from toptraj.planners.execution.memory import DEFAULT_SEARCH_MEMORY
from toptraj.robots.store import DEFAULT_MAX_BYTES, DEFAULT_MAX_UPLOADS, default_data_dir
from toptraj.robots.uploads import DEFAULT_CACHE_SIZE
from toptraj.service.body_limit import DEFAULT_MAX_BODY_BYTES
from toptraj.service.web import GUIDE


class Settings(BaseSettings):
    """Limits of the HTTP edge and where data lives.

    Attributes:
        max_body_bytes: Largest request body accepted (413 beyond).
        plan_budget_s: Wall-clock budget of one planning request (504 beyond), in s.
        preload_robots: Build every catalog robot at start-up rather than on first use.
        data_dir: Directory of the durable data (uploaded URDFs in ``uploads.sqlite3``); default
            ``$XDG_DATA_HOME/toptraj`` or ``~/.local/share/toptraj``.
        max_uploads: Most uploaded robots the store keeps (409 beyond).
        max_upload_bytes: Most bytes of distinct URDF text the store keeps (409 beyond).
        upload_cache_size: Most upload models a process keeps built in memory (least recently
            used dropped first).
        max_response_bytes: Largest trajectory body served; an ``output.dt`` whose samples
            would not fit gets 422 naming the smallest ``dt`` that does.
        plan_workers: Plannings run at once in this process, each in a thread (default: the
            number of cores; under ``toptraj serve --workers N``, the cores divided by N, at
            least 1: a process's planning threads share one interpreter lock, so more threads
            add no throughput, and N processes then run as many plannings as there are cores).
        plan_leash_s: How long a small planning (``toptraj.service.planning.worth_a_leash``) is first
            tried on the event loop when its process holds no other planning nor connection,
            in s (``PlanningWorkers.run``; 0: always in a thread).
        plan_queue: Requests that may wait for a planning worker of this process (within
            their budget); beyond, 503 with ``Retry-After``.
        plan_heavy_workers: Heavy plannings (``toptraj.service.planning.heavy``: search, collocation,
            jerk_limited, min_cost on large grids) run at once in this process, in threads of
            their own: they never take the threads of ``plan_workers``.
        plan_heavy_queue: Heavy plannings that may wait for a heavy worker of this process
            (within their budget); beyond, 503 with ``Retry-After``.
        search_memory_bytes: Most memory one search may take by its estimate
            (``toptraj.planners.generators.search.memory``, 2 GiB by default): beyond, 422 naming the largest
            ``roadmap_points``, ``neighbors`` or ``cells`` served.
        job_workers: Jobs (``/v1/jobs``) running at once, each in a worker process, over every
            server process on the data directory (default: half the cores, at least 1).
        job_budget_s: Default computing time of a job once running, in s.
        job_max_budget_s: Largest ``budget_s`` a job may ask for, in s (422 beyond).
        job_queue: Jobs that may wait for a job worker; beyond, 503 with ``Retry-After``.
        max_jobs: Most jobs the job store keeps (``jobs.sqlite3``); the oldest ended go first.
        job_max_age_s: Seconds an ended job is kept, at most.
        max_job_store_bytes: Most bytes of requests, answers and errors the job store keeps.
        telemetry: FastAPI's OpenTelemetry instrumentation of each request (spans, metrics and
            logs through the process's OpenTelemetry providers, ``FastAPI(telemetry=...)``).
            Off by default: the service sets up no provider, and the instrumentation's checks
            on every request cost time even then.
        ray_address: A Ray cluster for batches (``POST /v1/batches``): ``auto``,
            ``ray://host:port`` or ``local`` (a Ray started in the job's process); none: a batch
            runs in the server's own job worker process.
        guide_dir: The built documentation site served at ``/guide/`` (``make guide`` builds it
            into ``service/web/guide``).
    """

    model_config = SettingsConfigDict(env_prefix="TOPTRAJ_")

    max_body_bytes: int = DEFAULT_MAX_BODY_BYTES
    plan_budget_s: float = 20.0
    preload_robots: bool = True
    data_dir: Path = Field(default_factory=default_data_dir)
    max_uploads: int = Field(default=DEFAULT_MAX_UPLOADS, ge=1)
    max_upload_bytes: int = Field(default=DEFAULT_MAX_BYTES, ge=1)
    upload_cache_size: int = Field(default=DEFAULT_CACHE_SIZE, ge=1)
    max_response_bytes: int = Field(default=20_000_000, ge=1_000_000)
    plan_workers: int = Field(default_factory=lambda: os.cpu_count() or 1, ge=1)
    plan_leash_s: float = Field(default=0.02, ge=0.0, le=0.1)
    plan_queue: int = Field(default=8, ge=0)
    plan_heavy_workers: int = Field(default=1, ge=1)
    plan_heavy_queue: int = Field(default=2, ge=0)
    search_memory_bytes: int = Field(default=DEFAULT_SEARCH_MEMORY, ge=2**20)
    job_workers: int = Field(default_factory=lambda: max(1, (os.cpu_count() or 1) // 2), ge=1)
    job_budget_s: float = Field(default=300.0, gt=0)
    job_max_budget_s: float = Field(default=3_600.0, gt=0)
    job_queue: int = Field(default=100, ge=0)
    max_jobs: int = Field(default=1_000, ge=1)
    job_max_age_s: float = Field(default=7 * 86_400.0, gt=0)
    max_job_store_bytes: int = Field(default=1_000_000_000, ge=1_000_000)
    telemetry: bool = False
    ray_address: str | None = None
    guide_dir: Path = GUIDE

    @model_validator(mode="after")
    def _room_for_ended_jobs(self) -> Settings:
        """The job store keeps more jobs than may wait and run at once: else a job's answer is
        deleted as it ends, to make room for those still waiting."""
        active = self.job_queue + self.job_workers
        if self.max_jobs <= active:
            raise ValueError(
                f"TOPTRAJ_MAX_JOBS = {self.max_jobs} leaves no room for an ended job's answer beside the "
                f"{active} jobs that may wait and run at once (TOPTRAJ_JOB_QUEUE + TOPTRAJ_JOB_WORKERS): "
                f"set it above {active}, or lower those"
            )
        return self
