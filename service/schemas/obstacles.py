"""Schemas of a path's obstacles, its clearance from them and its self-collision check (part of
``toptraj.service.schemas.trajectories``'s waypoint and Cartesian paths)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field

from toptraj.planners.collision.self_collision import PADDING
from toptraj.service.schemas.common import Schema
from toptraj.service.schemas.geometry import OrientedBox, Point

MAX_OBSTACLES = 100


class SphereObstacleRequest(Schema):
    """A ball in the world frame."""

    kind: Literal["sphere"] = Field(description="`sphere`.")
    center: Point = Field(description="Center [x, y, z] (m), world frame.")
    radius: Annotated[float, Field(gt=0.0, le=100.0)] = Field(description="Radius (m).")


class BoxObstacleRequest(OrientedBox):
    """An oriented box in the world frame."""

    kind: Literal["box"] = Field(description="`box`.")


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
