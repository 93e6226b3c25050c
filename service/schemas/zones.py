"""Schema of ``timing.zones``: limits of their own on an s-range of the path or inside a region
of the workspace (``toptraj.planners.problem.zones``)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import Field, model_validator

from toptraj.planners.problem import ranges
from toptraj.planners.problem.zones import MAX_ZONES
from toptraj.service.schemas.common import Schema, bounded
from toptraj.service.schemas.geometry import OrientedBox, Point

Factor = Annotated[float, Field(gt=0.0, le=1.0)]


class ZoneSphere(Schema):
    """A ball in the world frame."""

    center: Point = Field(description="Center [x, y, z] (m), world frame.")
    radius: Annotated[float, Field(gt=0.0, le=100.0)] = Field(description="Radius (m).")


class ZoneBox(OrientedBox):
    """An oriented box in the world frame."""


class ZoneRequest(Schema):
    """Limits of their own where the zone applies: on `s_range` of the path, or where the tool
    point (the origin of timing.limits.tool_frame, else the end effector) is inside `sphere` or
    `box`. The robot's limits hold elsewhere, in the same timing."""

    s_range: Annotated[list[Annotated[float, Field(ge=0.0, le=1.0)]], Field(min_length=2, max_length=2)] | None = Field(
        default=None, description="[s0, s1] with 0 <= s0 < s1 <= 1: the part of the path (s from 0 at the start to 1 at the end)."
    )
    sphere: ZoneSphere | None = Field(default=None, description="A ball the tool point is inside (world frame).")
    box: ZoneBox | None = Field(default=None, description="An oriented box the tool point is inside (world frame).")
    velocity_scale: Factor | None = Field(default=None, description="Factor in (0, 1] on every joint velocity limit inside the zone.")
    acceleration_scale: Factor | None = Field(default=None, description="Factor in (0, 1] on every joint acceleration limit inside the zone.")
    torque_scale: Factor | None = Field(default=None, description="Factor in (0, 1] on every joint torque limit inside the zone.")
    tool_speed: Annotated[float, bounded(ranges.TOOL_SPEED)] | None = Field(
        default=None, description="Largest linear speed of the tool point inside the zone (m/s)."
    )

    @model_validator(mode="after")
    def _one_place_and_a_limit(self) -> ZoneRequest:
        places = [name for name in ("s_range", "sphere", "box") if getattr(self, name) is not None]
        if len(places) != 1:
            raise ValueError(f"give exactly one of s_range, sphere and box; got {' and '.join(places) or 'none'}")
        if self.s_range is not None and self.s_range[0] >= self.s_range[1]:
            s0, s1 = self.s_range
            length = "runs backwards" if s0 > s1 else "has zero length"
            raise ValueError(f"s_range [{s0:g}, {s1:g}] {length}: the zone covers no part of the path; give [s0, s1] with s1 > s0")
        limits = ("velocity_scale", "acceleration_scale", "torque_scale", "tool_speed")
        if all(getattr(self, name) is None for name in limits):
            raise ValueError(f"the zone sets no limit; give one of {', '.join(limits)}")
        return self


ZONES: Any = Field(
    default=[],
    max_length=MAX_ZONES,
    description=f"At most {MAX_ZONES} zones with limits of their own (phase_plane and toppra on a given path); the "
    "answer's `zones` says where each lies and whether it bound the timing.",
)
