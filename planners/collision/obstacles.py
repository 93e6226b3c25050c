"""Obstacles in the world frame (m): spheres, oriented boxes and capsules."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from toptraj.planners.errors import InvalidRequest

#: How far from 1 the norm of a box's orientation quaternion may be (rounded printing), as for
#: the poses of a cartesian path.
UNIT_TOLERANCE = 1e-3


@dataclass(frozen=True)
class SphereObstacle:
    """A ball: ``center`` (3,) and ``radius``."""

    center: np.ndarray
    radius: float
    kind: str = "sphere"


@dataclass(frozen=True)
class BoxObstacle:
    """An oriented box: ``center`` (3,), edge lengths ``size`` (3,) and ``orientation`` as a
    unit quaternion (qx, qy, qz, qw) from the box's axes to the world's."""

    center: np.ndarray
    size: np.ndarray
    orientation: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    kind: str = "box"

    @property
    def rotation(self) -> np.ndarray:
        """The rotation matrix (3, 3) of ``orientation`` (normalized)."""
        x, y, z, w = np.asarray(self.orientation, dtype=float) / np.linalg.norm(self.orientation)
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ])


@dataclass(frozen=True)
class CapsuleObstacle:
    """The points within ``radius`` of the segment from ``a`` to ``b`` (3,) each."""

    a: np.ndarray
    b: np.ndarray
    radius: float
    kind: str = "capsule"


Obstacle = SphereObstacle | BoxObstacle | CapsuleObstacle


def check_obstacles(obstacles: tuple[Obstacle, ...] | list[Obstacle]) -> None:
    """InvalidRequest naming the obstacle unless every box's orientation is a unit quaternion
    (norm within ``UNIT_TOLERANCE`` of 1): a zero or tiny one has no rotation to normalize to."""
    for index, obstacle in enumerate(obstacles):
        if not isinstance(obstacle, BoxObstacle):
            continue
        quaternion = np.asarray(obstacle.orientation, dtype=float)
        norm = float(np.linalg.norm(quaternion)) if quaternion.shape == (4,) else math.nan
        if not abs(norm - 1.0) <= UNIT_TOLERANCE:
            raise InvalidRequest(f"obstacles[{index}].orientation", obstacle.orientation, rule="orientation_not_unit", norm=norm)
