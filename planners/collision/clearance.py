"""The clearance of a path from the obstacles: every link capsule (``toptraj.robots.collision``)
against every obstacle, at configurations dense enough to bound the distance in between.

Between two configurations a point of the arm moves at most R * sum_j |dq_j|, R bounding its
distance from every joint (each joint turns the part beyond it by |dq_j|), so the distance
between two checked configurations is at least the smaller of their distances minus half that
motion. A first pass checks configurations ``COARSE_STEP`` of motion apart; where that bound
comes within the clearance, the interval is split to ``RESOLUTION`` and checked again. A path
is refused when a checked configuration is closer than the clearance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from toptraj.planners.collision.distance import capsule_distance
from toptraj.planners.collision.obstacles import Obstacle
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.robots import Robot
from toptraj.robots.collision import robot_capsules, world_capsules

if TYPE_CHECKING:
    from toptraj.planners.paths.base import GeometricPath

#: Largest motion (m) of any point of the arm between two configurations of the first pass.
COARSE_STEP = 0.02
#: Largest motion (m) between two configurations where the first pass comes near the clearance.
RESOLUTION = 1e-3
#: Most configurations of the first pass along one path.
MAX_CONFIGURATIONS = 5_000
#: Configurations of the first, coarse pass that bounds the path's motion.
COARSE = 200


class PathInCollision(InfeasiblePath):
    """The path comes closer to an obstacle than the clearance: ``link``, ``obstacle`` (its
    index in ``path.obstacles``) and ``s`` say where."""

    def __init__(self, detail: str, s: float, link: str, obstacle: int, **facts: Any):
        super().__init__(detail, s=s, link=link, obstacle=obstacle, rule="path_in_collision", **facts)


@dataclass(frozen=True)
class Clearance:
    """The smallest signed distance (m) between the robot's links and the obstacles along a
    path, the ``link`` and the ``obstacle`` (index) where it occurs, and its ``s``; and how
    many configurations were checked."""

    distance: float
    link: str
    obstacle: int
    s: float
    checked: int


def clearance_along(
    robot: Robot, q: np.ndarray, obstacles: list[Obstacle], exact_below: float = np.inf
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per configuration of ``q`` (n, n_dof): the smallest signed distance (m) to any obstacle,
    and the indices of the capsule and of the obstacle that give it; shapes (n,). Distances
    above ``exact_below`` may be lower bounds (``capsule_distance``), the smallest is exact."""
    capsules = robot_capsules(robot)
    a, b = world_capsules(robot.model, robot.data, capsules, robot.configuration(q))
    radius = np.array([c.radius for c in capsules])
    distances = np.stack([capsule_distance(a, b, radius, obstacle, exact_below) for obstacle in obstacles], axis=-1)  # (n, k, m)
    flat = distances.reshape(len(q), -1)
    best = flat.argmin(axis=1)
    capsule, obstacle = np.unravel_index(best, distances.shape[1:])
    return flat[np.arange(len(q)), best], capsule, obstacle


def _reach(robot: Robot) -> float:
    """A bound (m), whatever the configuration, on the distance from any joint to any point of
    the arm: the lengths between successive joints, plus the farthest capsule point from its
    own joint."""
    model = robot.model
    chain = sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in range(2, model.njoints))
    capsule = max(max(np.linalg.norm(c.a), np.linalg.norm(c.b)) + c.radius for c in robot_capsules(robot))
    return chain + float(capsule)


def _refined(s: np.ndarray, flagged: np.ndarray, pieces: int) -> np.ndarray:
    """``s`` with each flagged interval (s[i], s[i + 1]) split into ``pieces``."""
    inside = [np.linspace(s[i], s[i + 1], pieces + 1)[1:-1] for i in np.flatnonzero(flagged)]
    return np.unique(np.concatenate([s, *inside])) if inside else s


def _too_close(s, distances, capsule, obstacle, capsules, clearance: float, found: Clearance | None) -> None:
    """PathInCollision at the first configuration closer than ``clearance``, if any."""
    closer = np.flatnonzero(distances < clearance)
    if not closer.size:
        return
    first = int(closer[0])
    link, index, distance = capsules[capsule[first]].name, int(obstacle[first]), float(distances[first])
    how = f"is inside obstacle {index} (by {-distance:.4g} m)" if distance < 0 else f"comes within {distance:.4g} m of obstacle {index}"
    closest = "" if found is None else f"; the closest approach is {found.distance:.4g} m at s = {found.s:.4g}"
    raise PathInCollision(
        f"link {link!r} {how} at s = {s[first]:.4g} (the clearance is {clearance:g} m{closest})",
        s=float(s[first]),
        link=link,
        obstacle=index,
        distance=distance,
        clearance=clearance,
        closest=None if found is None else (found.distance, found.s),
    )


def check_clearance(
    path: GeometricPath, robot: Robot, obstacles: list[Obstacle], clearance: float, deadline: Deadline = NO_DEADLINE
) -> Clearance:
    """The clearance of ``path`` (a ``GeometricPath``) from ``obstacles``, checked where it
    matters: configurations at most ``COARSE_STEP`` of arm motion apart, and those intervals
    whose ends are within their motion of the clearance split to ``RESOLUTION``.

    Raises:
        PathInCollision: a link comes closer than ``clearance`` (m) to an obstacle.
    """
    reach = _reach(robot)
    capsules = robot_capsules(robot)
    coarse_s = np.linspace(0.0, 1.0, COARSE + 1)
    coarse_q = path.evaluate(coarse_s).q
    # a first look: a path through an obstacle is refused without the dense pass
    _too_close(coarse_s, *clearance_along(robot, coarse_q, obstacles, clearance), capsules, clearance, None)
    motion = reach * np.abs(np.diff(coarse_q, axis=0)).sum()
    count = min(MAX_CONFIGURATIONS, max(COARSE, math.ceil(motion / COARSE_STEP))) + 1
    s = np.linspace(0.0, 1.0, count)
    q = path.evaluate(s).q
    exact_below = clearance + COARSE_STEP
    distances, capsule, obstacle = clearance_along(robot, q, obstacles, exact_below)
    _too_close(s, distances, capsule, obstacle, capsules, clearance, None)  # no need to look closer
    deadline.check()
    step = reach * np.abs(np.diff(q, axis=0)).sum(axis=1)
    near = np.minimum(distances[:-1], distances[1:]) - step / 2.0 < clearance
    if near.any():
        pieces = int(min(100, max(2, math.ceil(step[near].max() / RESOLUTION))))
        pieces = max(2, min(pieces, MAX_CONFIGURATIONS // int(near.sum())))
        s = _refined(s, near, pieces)
        q = path.evaluate(s).q
        distances, capsule, obstacle = clearance_along(robot, q, obstacles, exact_below)
    worst = int(np.argmin(distances))
    found = Clearance(float(distances[worst]), capsules[capsule[worst]].name, int(obstacle[worst]), float(s[worst]), len(s))
    _too_close(s, distances, capsule, obstacle, capsules, clearance, found)
    return found
