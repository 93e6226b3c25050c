"""Schemas of the robot resource."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field

from robots.uploads import MAX_NAME_CHARS, NAME_PATTERN
from service.schemas.common import Schema

MAX_URDF_CHARS = 1_000_000


class RobotSummary(BaseModel):
    """One line of the catalog."""

    name: str
    dof: int
    source: Literal["bundled", "example-robot-data", "upload"]


class RobotLimits(BaseModel):
    """Per-joint limits in SI units (rad, rad/s, rad/s^2, rad/s^3, N m); ``null`` is unlimited."""

    position_lower: list[float | None]
    position_upper: list[float | None]
    velocity: list[float | None]
    acceleration: list[float | None]
    jerk: list[float | None]
    torque: list[float | None]


class RobotPublic(BaseModel):
    """A robot as the service sees it."""

    name: str
    dof: int
    source: str
    joint_names: list[str]
    end_effector: str
    limits: RobotLimits


class RobotCreate(Schema):
    """An uploaded URDF, optionally under a chosen name."""

    name: str | None = Field(
        default=None,
        max_length=MAX_NAME_CHARS,
        pattern=f"^{NAME_PATTERN.pattern}$",
        description="Name to keep it under (a letter, then up to 63 letters, digits, `_`, `.` or `-`); "
        "default `urdf-` plus a content hash.",
    )
    urdf: str = Field(max_length=MAX_URDF_CHARS, description="The URDF text (fixed-base arm).")
