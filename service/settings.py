"""Service settings, read from ``TOPTRAJ_*`` environment variables."""

from __future__ import annotations

import os

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    """Limits of the HTTP edge.

    Attributes:
        max_body_bytes: Largest request body accepted (413 beyond).
        plan_budget_s: Wall-clock budget of one planning request (504 beyond), in s.
        preload_robots: Build every catalog robot at start-up rather than on first use.
        max_response_bytes: Largest trajectory body served; an ``output.dt`` whose samples
            would not fit gets 422 naming the smallest ``dt`` that does.
        plan_workers: Plannings run at once (default: the number of cores).
        plan_queue: Requests that may wait for a planning worker (within their budget); beyond,
            503 with ``Retry-After``.
    """

    model_config = SettingsConfigDict(env_prefix="TOPTRAJ_")

    max_body_bytes: int = 2_000_000
    plan_budget_s: float = 20.0
    preload_robots: bool = True
    max_response_bytes: int = Field(default=20_000_000, ge=1_000_000)
    plan_workers: int = Field(default_factory=lambda: os.cpu_count() or 1, ge=1)
    plan_queue: int = Field(default=8, ge=0)
