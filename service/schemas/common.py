"""Shared pydantic configuration: reject unknown fields and NaN/inf at the edge."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class Schema(BaseModel):
    """Base of every request schema: extra fields and non-finite numbers are errors."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class Problem(BaseModel):
    """An RFC 9457 problem, as every error answer carries it."""

    type: str = "about:blank"
    title: str
    status: int
    detail: str
