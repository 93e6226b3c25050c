"""The planning problem, built once and validated at the library's edge
(``toptraj.planners.problem.build.build_problem``): everything after it trusts it.

A ``Problem`` says what to move (the robot and its motion: a given path, via points or end
points), by which method (a timing method along a given path, or a motion generator that finds
the motion itself), under which limits (with the margin applied and the tool limit added),
sampled how, among which obstacles and within which deadline.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from toptraj.planners.collision import Obstacle
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.requests import Timing, WaypointPath
from toptraj.planners.timing.base import TimingMethod
from toptraj.robots import JointLimits, Robot

if TYPE_CHECKING:
    from toptraj.planners.problem.methods import MotionGenerator

#: What a problem moves along: joint waypoints (interpolated, or via points), a Cartesian line,
#: or a free motion from a start to a goal.
MotionSpec = WaypointPath | CartesianLine | FreeMotion


@dataclass(frozen=True)
class Sampling:
    """How the answer is sampled: every ``dt`` seconds, into at most ``max_samples`` samples;
    with ``exact_period`` on whole periods, the final state included."""

    dt: float = 0.01
    max_samples: int = 200_000
    exact_period: bool = False


@dataclass(frozen=True)
class Problem:
    """A validated planning problem.

    Attributes:
        robot: The arm (Pinocchio model, joint names, catalog limits).
        motion: What to move along, after repeated waypoints are dropped and continuous joints'
            turns are resolved.
        method: A ``TimingMethod`` (times a given path) or a ``MotionGenerator`` (finds the
            motion itself); ``method.family`` tells which.
        options: The timing options as asked (boundary states, duration, grid, law options).
        kinds: The limit kinds applied: the asked ones plus those the method always applies.
        limits: The limits the timing is planned under: overrides and scales applied, the
            tool-speed limit added, tightened by ``margin``; (n_dof,) each, SI units.
        margin: Fraction of every limit kept in reserve, in [0, 0.5].
        threshold: Largest |value| / limit the limit gate lets through (from ``margin``).
        sampling: How the answer is sampled.
        obstacles: Obstacles in the world frame; ``clearance`` (m) is kept from them.
        deadline: Budget, cancellation and progress of the whole planning.
        notes: What the build changed (waypoints dropped, turns taken), told in the answer.
        self_collision: Whether no two links may touch along the path (the search checks it
            always).
    """

    robot: Robot
    motion: MotionSpec
    method: TimingMethod | MotionGenerator
    options: Timing
    kinds: tuple[str, ...]
    limits: JointLimits
    margin: float
    threshold: float
    sampling: Sampling
    obstacles: tuple[Obstacle, ...]
    clearance: float
    deadline: Deadline
    notes: tuple[str, ...] = ()
    self_collision: bool = False
