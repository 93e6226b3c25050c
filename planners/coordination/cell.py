"""A robot cell: arms sharing one world, each with its base pose, its own given path and its
limits, and the clearance they must keep from each other (path-velocity decomposition, Kant &
Zucker 1986: each path is fixed, only the timing along it is chosen).

Geometry and dynamics: every arm's robot is mounted by its base pose (``toptraj.robots.equipment``:
p_world = R p_base + t, R (3, 3) the base's axes in the world, t (3,) in m, gravity as the base
feels it) and carries its payload, so that its link capsules (``toptraj.robots.collision``) are
in the world and its torques include both. The distance
between two arms is the smallest capsule-to-capsule distance (segments as in Ericson,
*Real-Time Collision Detection*, §5.1.9, minus both radii), in m, negative when they overlap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.collision.clearance import sliding_travel
from toptraj.planners.collision.distance import segment_distance
from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.problem.bounded import check_speed_bounded
from toptraj.robots import JointLimits, Robot
from toptraj.robots.collision import robot_capsules, world_capsules

#: Arms a cell holds: two coordinated in full (the square of their path parameters), more by
#: prioritized planning over every order of the arms (``prioritized``: 4! = 24 orders, 6 pairwise
#: diagrams).
MAX_ARMS = 4
#: The limit kinds a cell holds (its timings are TOPP-RA's: no jerk).
CELL_KINDS = ("velocity", "acceleration", "torque")


@dataclass(frozen=True)
class CellArm:
    """One arm of a cell: its ``robot`` (mounted by its base pose in the world and carrying its
    payload, ``toptraj.robots.equipment.equip``), its given ``path`` (s in [0, 1]) and its
    ``limits``."""

    robot: Robot
    path: GeometricPath
    limits: JointLimits

    @property
    def base_rotation(self) -> np.ndarray:
        """The base's axes in the world (3, 3)."""
        mounting = self.robot.mounting
        return np.eye(3) if mounting is None else np.array(mounting.rotation, dtype=float).reshape(3, 3)

    @property
    def base_position(self) -> np.ndarray:
        """The base's origin in the world (3,), m."""
        mounting = self.robot.mounting
        return np.zeros(3) if mounting is None else np.array(mounting.position, dtype=float)

    def capsules_at(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World end points a, b (n, k, 3) of the arm's k capsules at joint positions ``q``
        (n, n_dof), and their radii (k,), in m (the mounted model's kinematics are the world's)."""
        capsules = robot_capsules(self.robot)
        a, b = world_capsules(self.robot.model, self.robot.data, capsules, self.robot.configuration(q))
        return a, b, np.array([capsule.radius for capsule in capsules])

    def link_names(self) -> list[str]:
        """The names of the arm's capsules, in the order of ``capsules_at``."""
        return [capsule.link or capsule.name for capsule in robot_capsules(self.robot)]

    def reach(self) -> float:
        """A bound (m) on how far any point of the arm lies from any of its joints, so that a
        joint motion dq moves no point by more than reach * sum |dq_j|."""
        model = self.robot.model
        chain = sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in range(2, model.njoints))
        moving = [c for c in robot_capsules(self.robot) if c.joint != 0]  # the base's capsules never move
        tip = max(max(np.linalg.norm(c.a), np.linalg.norm(c.b)) + c.radius for c in moving)
        reach = chain + sliding_travel(self.robot) + float(tip)
        return max(reach, 1.0) if "N" in self.robot.force_units else reach  # a slide of |dq| moves points by |dq|


@dataclass(frozen=True)
class Cell:
    """Arms sharing a workspace, to be kept ``clearance`` (m) apart, under the limit ``kinds``
    (velocity, acceleration, torque) of each."""

    arms: tuple[CellArm, ...]
    clearance: float
    kinds: tuple[str, ...] = ("velocity", "acceleration")

    def __post_init__(self) -> None:
        """Every arm's motion is bounded by the limits of ``kinds`` it has
        (``toptraj.planners.problem.bounded``: an arm with none would be timed at zero).

        Raises:
            InvalidRequest: field ``arms[i]``, rule "no_limit_bounds_speed".
        """
        for index, arm in enumerate(self.arms):
            check_speed_bounded(arm.robot, arm.limits, self.kinds, served=CELL_KINDS, field=f"arms[{index}]")


def pair_distances(first: tuple[np.ndarray, np.ndarray, np.ndarray], second: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smallest distance (m) between two arms' capsules, pairwise over leading axes: ``first``
    = (a, b, radius) with a, b of shape (..., k1, 3) and ``second`` likewise (..., k2, 3);
    returns the distances (...) and the indices of the two capsules that give them."""
    a1, b1, r1 = first
    a2, b2, r2 = second
    d = segment_distance(a1[..., :, None, :], b1[..., :, None, :], a2[..., None, :, :], b2[..., None, :, :])
    d = d - r1[:, None] - r2[None, :]
    flat = d.reshape(*d.shape[:-2], -1)
    best = flat.argmin(axis=-1)
    distance = np.take_along_axis(flat, best[..., None], axis=-1)[..., 0]
    return distance, best // d.shape[-1], best % d.shape[-1]
