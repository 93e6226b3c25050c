"""Shapes in the world frame that several requests share: a point, and an oriented box (an
obstacle of a path, a zone of limits)."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from toptraj.planners.problem import ranges
from toptraj.service.schemas.common import Schema, signed

Point = Annotated[list[Annotated[float, signed(ranges.COORDINATE)]], Field(min_length=3, max_length=3)]


class OrientedBox(Schema):
    """An oriented box in the world frame."""

    center: Point = Field(description="Center [x, y, z] (m), world frame.")
    size: Annotated[list[Annotated[float, Field(gt=0.0, le=100.0)]], Field(min_length=3, max_length=3)] = Field(
        description="Edge lengths [sx, sy, sz] (m) along the box's own axes."
    )
    orientation: Annotated[list[Annotated[float, Field(ge=-1.0, le=1.0)]], Field(min_length=4, max_length=4)] = Field(
        default=[0.0, 0.0, 0.0, 1.0], description="Unit quaternion [qx, qy, qz, qw] from the box's axes to the world's (norm 1 within 1e-3)."
    )
