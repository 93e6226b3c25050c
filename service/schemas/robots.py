"""Schemas of the robot resource."""

from __future__ import annotations

from typing import Annotated, Literal

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


MAX_CONFIGURATIONS = 1_000


class SkeletonRequest(Schema):
    """Joint configurations to draw (rad, m), one row each."""

    q: list[Annotated[list[float], Field(min_length=1, max_length=64)]] = Field(
        min_length=1, max_length=MAX_CONFIGURATIONS, description="Joint configurations (rad, m), one row each."
    )


class SkeletonPublic(BaseModel):
    """World positions (m) of each joint origin and of the end effector, per configuration:
    ``positions[k][i]`` is point ``points[i]`` in configuration k."""

    points: list[str]
    positions: list[list[list[float]]]
