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
    """The path comes closer to an obstacle than the clearance: ``link`` (the URDF's link),
    ``obstacle`` (its index in ``path.obstacles``) and ``s`` say where; ``fixed``, when given,
    whether that link is fixed to the base (no joint moves it)."""

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
    """A bound R (m), whatever the configuration, on the distance from any joint to any point of
    the arm (the lengths between successive joints, plus the farthest capsule point from its
    own joint), so that a joint motion dq moves no point by more than R sum |dq_j|: a revolute
    joint turning by |dq| moves a point at most R |dq|, a prismatic one sliding by |dq| exactly
    |dq|, so R is at least 1 on an arm with a prismatic joint."""
    model = robot.model
    chain = sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in range(2, model.njoints))
    capsule = max(max(np.linalg.norm(c.a), np.linalg.norm(c.b)) + c.radius for c in robot_capsules(robot))
    reach = chain + sliding_travel(robot) + float(capsule)
    return max(reach, 1.0) if "N" in robot.force_units else reach


#: Largest travel (m) counted for a prismatic joint: a joint coordinate of a request lies within
#: 1e4 (``toptraj.planners.problem.waypoints.MAX_COORDINATE``), so a slide without limits too.
MAX_TRAVEL = 1e4


def sliding_travel(robot: Robot) -> float:
    """How far (m) the prismatic joints can carry the links beyond them from where the zero
    configuration puts them: the sum of each one's largest |position limit|, at most
    ``MAX_TRAVEL`` (the joint lengths of ``_reach`` are those at zero)."""
    sliding = np.array([unit == "N" for unit in robot.force_units])
    if not sliding.any():
        return 0.0
    lower, upper = robot.limits.position_lower[sliding], robot.limits.position_upper[sliding]
    return float(np.minimum(np.maximum(np.abs(lower), np.abs(upper)), MAX_TRAVEL).sum())


def _dense_grid(reach: float, coarse_q: np.ndarray) -> np.ndarray:
    """The uniform grid of s whose configurations lie at most ``COARSE_STEP`` of arm motion
    apart, judged on the coarse pass's configurations ``coarse_q`` (within ``COARSE`` and
    ``MAX_CONFIGURATIONS`` points)."""
    motion = reach * np.abs(np.diff(coarse_q, axis=0)).sum()
    return np.linspace(0.0, 1.0, min(MAX_CONFIGURATIONS, max(COARSE, math.ceil(motion / COARSE_STEP))) + 1)


def _split_near(s: np.ndarray, near: np.ndarray, step: np.ndarray) -> np.ndarray:
    """``s`` with the ``near`` intervals (their arm motion ``step``, m) split to ``RESOLUTION``
    of motion, within ``MAX_CONFIGURATIONS`` new points in all."""
    pieces = int(min(100, max(2, math.ceil(step[near].max() / RESOLUTION))))
    return _refined(s, near, max(2, min(pieces, MAX_CONFIGURATIONS // int(near.sum()))))


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
    touching = capsules[capsule[first]]
    link, index, distance = touching.link, int(obstacle[first]), float(distances[first])
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
        fixed=touching.joint == 0,
    )


def check_clearance(
    path: GeometricPath, robot: Robot, obstacles: list[Obstacle], clearance: float, deadline: Deadline = NO_DEADLINE,
    explain: bool = True,
) -> Clearance:
    """The clearance of ``path`` (a ``GeometricPath``) from ``obstacles``, checked where it
    matters: configurations at most ``COARSE_STEP`` of arm motion apart, and those intervals
    whose ends are within their motion of the clearance split to ``RESOLUTION``.

    Raises:
        PathInCollision: a link comes closer than ``clearance`` (m) to an obstacle; its
            ``least`` a lower bound on the path's distance from them (``closest_approach``, a
            second pass over the whole path: the first stops where it first comes too close),
            unless ``explain`` is false (a caller that only needs to know).
    """
    try:
        return _checked(path, robot, obstacles, clearance, deadline)
    except PathInCollision as error:
        if not explain:
            raise
        least, at = closest_approach(path, robot, obstacles, deadline)
        facts = {key: value for key, value in vars(error).items() if key not in ("detail", "rule")}
        raise PathInCollision(
            f"{error.detail}; the path comes no closer than {least:.4g} m, near s = {at:.4g}", **facts, least=least, least_s=at
        ) from None


def closest_approach(path: GeometricPath, robot: Robot, obstacles: list[Obstacle], deadline: Deadline = NO_DEADLINE) -> tuple[float, float]:
    """A lower bound (m) on the distance between the arm and ``obstacles`` along the whole of
    ``path`` (negative inside one), within about ``RESOLUTION`` / 2 of it, and the s where the
    sampled distance is least: exact distances at configurations ``COARSE_STEP`` of arm motion
    apart, the intervals that may hold the least split to ``RESOLUTION``; between two samples
    the distance is at least the smaller end's less half the interval's motion, so that a
    clearance no larger than the bound lets the path through any check."""
    reach = _reach(robot)
    s = _dense_grid(reach, path.evaluate(np.linspace(0.0, 1.0, COARSE + 1)).q)
    for attempt in range(2):  # the samples, then the intervals that may hold the least, split
        deadline.check()
        q = path.evaluate(s).q
        distances, _, _ = clearance_along(robot, q, obstacles)
        step = reach * np.abs(np.diff(q, axis=0)).sum(axis=1)
        lower = np.minimum(distances[:-1], distances[1:]) - step / 2.0
        near = lower < distances.min()
        if attempt == 1 or not near.any() or step[near].max() <= RESOLUTION:
            break
        s = _split_near(s, near, step)
    return float(min(lower.min(), distances.min())), float(s[int(np.argmin(distances))])


def _checked(path: GeometricPath, robot: Robot, obstacles: list[Obstacle], clearance: float, deadline: Deadline) -> Clearance:
    """``check_clearance`` without the second pass."""
    reach = _reach(robot)
    capsules = robot_capsules(robot)
    coarse_s = np.linspace(0.0, 1.0, COARSE + 1)
    coarse_q = path.evaluate(coarse_s).q
    # a first look: a path through an obstacle is refused without the dense pass
    _too_close(coarse_s, *clearance_along(robot, coarse_q, obstacles, clearance), capsules, clearance, None)
    s = _dense_grid(reach, coarse_q)
    q = path.evaluate(s).q
    exact_below = clearance + COARSE_STEP
    distances, capsule, obstacle = clearance_along(robot, q, obstacles, exact_below)
    _too_close(s, distances, capsule, obstacle, capsules, clearance, None)  # no need to look closer
    deadline.check()
    step = reach * np.abs(np.diff(q, axis=0)).sum(axis=1)
    near = np.minimum(distances[:-1], distances[1:]) - step / 2.0 < clearance
    if near.any():
        s = _split_near(s, near, step)
        q = path.evaluate(s).q
        distances, capsule, obstacle = clearance_along(robot, q, obstacles, exact_below)
    worst = int(np.argmin(distances))
    found = Clearance(float(distances[worst]), capsules[capsule[worst]].link, int(obstacle[worst]), float(s[worst]), len(s))
    _too_close(s, distances, capsule, obstacle, capsules, clearance, found)
    return found
