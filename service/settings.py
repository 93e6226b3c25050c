"""Service settings, read from ``TOPTRAJ_*`` environment variables."""

from __future__ import annotations

from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    """Limits of the HTTP edge.

    Attributes:
        max_body_bytes: Largest request body accepted (413 beyond).
        plan_budget_s: Wall-clock budget of one planning request (504 beyond), in s.
        preload_robots: Build every catalog robot at start-up rather than on first use.
    """

    model_config = SettingsConfigDict(env_prefix="TOPTRAJ_")

    max_body_bytes: int = 2_000_000
    plan_budget_s: float = 20.0
    preload_robots: bool = True
