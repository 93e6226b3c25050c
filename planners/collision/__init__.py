"""Obstacles in the world and the robot's clearance from them along a path (Jeong & Lee §2's
configuration-space obstacles start here): ``obstacles`` (plain domain objects), ``distance``
(capsule-to-obstacle distances, vectorized) and ``clearance`` (a path checked densely)."""

from toptraj.planners.collision.clearance import Clearance, check_clearance, clearance_along
from toptraj.planners.collision.obstacles import BoxObstacle, CapsuleObstacle, Obstacle, SphereObstacle

__all__ = [
    "BoxObstacle",
    "CapsuleObstacle",
    "Clearance",
    "Obstacle",
    "SphereObstacle",
    "check_clearance",
    "clearance_along",
]
