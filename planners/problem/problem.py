"""The planning problem, built once and validated at the library's edge
(``toptraj.planners.problem.build.build_problem``): everything after it trusts it.

A ``Problem`` says what to move (the robot and its motion: a given path, via points or end
points), by which method (a timing method along a given path, or a motion generator that finds
the motion itself), under which limits (with the margin applied and the tool limit added),
sampled how, among which obstacles and within which deadline.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from toptraj.planners.collision import Obstacle
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.execution.memory import MAX_SAMPLES
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.zones import Zone
from toptraj.planners.timing.base import TimingMethod
from toptraj.robots import JointLimits, Robot

if TYPE_CHECKING:
    from toptraj.planners.problem.methods import MotionGenerator

#: What a problem moves along: joint waypoints (interpolated, or via points), a Cartesian line,
#: or a free motion from a start to a goal.
MotionSpec = WaypointPath | CartesianLine | FreeMotion


@dataclass(frozen=True)
class LimitRequest:
    """The limits a problem is planned under, as asked.

    Attributes:
        kinds: Which limits to respect, among velocity, acceleration, jerk and torque (the
            method adds those it always applies); ``None``: ``DEFAULT_KINDS``, those of them the
            method holds (the others are left out and told in the answer's notes).
        overrides: Per-joint replacements of the robot's limits, keys ``velocity``,
            ``acceleration``, ``jerk``, ``torque``; (n_dof,) each, SI units.
        scales: Factors on those limits, same keys.
        margin: Fraction of every limit kept in reserve, in [0, 0.5]: the timing is planned
            under the limits times (1 - margin).
        tool_speed: Largest linear speed of the tool frame's origin, m/s; ``None``: none.
        tool_angular_speed: Largest angular speed of the tool frame, rad/s; ``None``: none.
        tool_frame: The frame those speeds limit; ``None``: the robot's end effector.
        zones: Limits of their own on parts of the path (``toptraj.planners.problem.zones.Zone``).
    """

    kinds: tuple[str, ...] | None = None
    overrides: dict[str, list[float] | None] = field(default_factory=dict)
    scales: dict[str, float | None] = field(default_factory=dict)
    margin: float = 0.0
    tool_speed: float | None = None
    tool_angular_speed: float | None = None
    tool_frame: str | None = None
    zones: tuple[Zone, ...] = ()


@dataclass(frozen=True)
class BoundaryStates:
    """The joint states at the ends of the motion: velocities (n_dof,) rad/s and accelerations
    (n_dof,) rad/s^2, ``None`` for rest. Velocities must be tangent to a given path."""

    start_velocity: ArrayLike | None = None
    end_velocity: ArrayLike | None = None
    start_acceleration: ArrayLike | None = None
    end_acceleration: ArrayLike | None = None

    @property
    def given(self) -> bool:
        """Whether any state is given (a zero included)."""
        return any(value is not None for value in self._states())

    @property
    def moving(self) -> bool:
        """Whether any state is given and not zero."""
        return any(value is not None and np.any(np.asarray(value) != 0.0) for value in self._states())

    @property
    def velocities_moving(self) -> bool:
        """Whether a start or end velocity is given and not zero."""
        return any(value is not None and np.any(np.asarray(value) != 0.0) for value in (self.start_velocity, self.end_velocity))

    def _states(self) -> tuple:
        return (self.start_velocity, self.end_velocity, self.start_acceleration, self.end_acceleration)


#: Boundary states of a motion from rest to rest.
AT_REST = BoundaryStates()


@dataclass(frozen=True)
class Sampling:
    """How the answer is sampled: every ``dt`` seconds, into at most ``max_samples`` samples;
    with ``exact_period`` on whole periods, the final state included."""

    dt: float = 0.01
    max_samples: int = MAX_SAMPLES
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
        requested: The limits as asked (kinds, overrides, scales, margin, tool limits, zones).
        grid: Grid intervals asked for; ``None``: chosen from the path.
        boundary: Joint states at the ends of the motion (``None`` entries: rest).
        duration: Seconds, for the methods that take one; ``None``: the shortest.
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
        unheld: Kinds of ``DEFAULT_KINDS`` left out because the method cannot hold them (the
            kinds were not asked for: ``requested.kinds`` is ``None``).
    """

    robot: Robot
    motion: MotionSpec
    method: TimingMethod | MotionGenerator
    requested: LimitRequest
    grid: int | None
    boundary: BoundaryStates
    duration: float | None
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
    unheld: tuple[str, ...] = ()
