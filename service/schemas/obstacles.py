"""Schemas of a path's obstacles, its clearance from them and its self-collision check (part of
``toptraj.service.schemas.trajectories``'s waypoint and Cartesian paths)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field

from toptraj.planners.collision.self_collision import PADDING
from toptraj.planners.problem import ranges
from toptraj.service.schemas.common import Schema, signed

Coordinate = Annotated[float, signed(ranges.COORDINATE)]
Point = Annotated[list[Coordinate], Field(min_length=3, max_length=3)]
MAX_OBSTACLES = 100


class SphereObstacleRequest(Schema):
    """A ball in the world frame."""

    kind: Literal["sphere"] = Field(description="`sphere`.")
    center: Point = Field(description="Center [x, y, z] (m), world frame.")
    radius: Annotated[float, Field(gt=0.0, le=100.0)] = Field(description="Radius (m).")


class BoxObstacleRequest(Schema):
    """An oriented box in the world frame."""

    kind: Literal["box"] = Field(description="`box`.")
    center: Point = Field(description="Center [x, y, z] (m), world frame.")
    size: Annotated[list[Annotated[float, Field(gt=0.0, le=100.0)]], Field(min_length=3, max_length=3)] = Field(
        description="Edge lengths [sx, sy, sz] (m) along the box's own axes."
    )
    orientation: Annotated[list[Annotated[float, Field(ge=-1.0, le=1.0)]], Field(min_length=4, max_length=4)] = Field(
        default=[0.0, 0.0, 0.0, 1.0], description="Unit quaternion [qx, qy, qz, qw] from the box's axes to the world's (norm 1 within 1e-3)."
    )


class CapsuleObstacleRequest(Schema):
    """The points within `radius` of the segment from `a` to `b`, world frame."""

    kind: Literal["capsule"] = Field(description="`capsule`.")
    a: Point = Field(description="One end of the axis [x, y, z] (m).")
    b: Point = Field(description="The other end of the axis [x, y, z] (m).")
    radius: Annotated[float, Field(gt=0.0, le=100.0)] = Field(description="Radius (m).")


ObstacleRequest = Annotated[
    SphereObstacleRequest | BoxObstacleRequest | CapsuleObstacleRequest, Field(discriminator="kind")
]
OBSTACLES: Any = Field(
    default=[],
    max_length=MAX_OBSTACLES,
    description="Obstacles in the world frame (spheres, boxes, capsules): every link keeps path.clearance "
    "from them along the path, else 422 naming the link, the obstacle and s; the answer reports min_clearance.",
)
CLEARANCE = Field(default=0.01, ge=0.0, le=1.0, description="Distance (m) every link keeps from every obstacle.")
SELF_COLLISION = Field(
    default=False,
    description="Whether to check that no two links of the arm touch along the path (adjacent links and the "
    "robot's allowed pairs excepted), else 422 naming the two links and s. timing.method `search` checks it always. "
    "Checked on capsules that contain the links' collision meshes: conservative, a path is refused where the meshes "
    f"may still be up to about {PADDING:g} m apart (ur5: 0.1 m), never accepted where they touch.",
)
