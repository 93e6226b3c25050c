"""``build_problem``: a robot, a motion and the timing options, validated once into a
``Problem`` (``toptraj.planners.problem.problem``).

The checks, in order: the method and its options (``method``, built by the caller: a timing
method or a motion generator), the constraint kinds against what the method serves, ranges of
the timing options and the obstacles, sampling against the boundary, the grid against the
method's memory, the margin, the limits with their overrides and scales, the tool-speed limit,
the waypoints (repeats dropped, continuous joints' turns), the method against the motion
(two waypoints only; what a generator serves). What can only be known from the path (its joint
range, its boundary tangents) is checked where the path is built.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.checks.gate import gate_threshold
from toptraj.planners.collision import Obstacle
from toptraj.planners.collision.obstacles import check_obstacles
from toptraj.planners.constraints.tool_speed import tool_speed_limit
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import MotionGenerator
from toptraj.planners.problem.problem import MotionSpec, Problem, Sampling
from toptraj.planners.problem.ranges import check_scaled_limits, check_timing
from toptraj.planners.problem.requests import Timing, WaypointPath, check_constraint_kinds
from toptraj.planners.problem.waypoints import continuous_turns, without_repeats
from toptraj.planners.timing.base import TimingMethod
from toptraj.robots import JointLimits, Robot

#: Most samples an answer holds unless the caller says otherwise.
MAX_SAMPLES = 200_000
#: Largest timing.limit_margin (a fraction of every limit kept in reserve).
MAX_LIMIT_MARGIN = 0.5
#: Distance (m) every link keeps from the obstacles unless a request says otherwise.
DEFAULT_CLEARANCE = 0.01


def build_problem(
    robot: Robot,
    motion: MotionSpec,
    method: TimingMethod | MotionGenerator,
    timing: Timing = Timing(),
    *,
    sampling: Sampling = Sampling(),
    obstacles: tuple[Obstacle, ...] = (),
    clearance: float = DEFAULT_CLEARANCE,
    deadline: Deadline = NO_DEADLINE,
) -> Problem:
    """The validated problem of moving ``robot`` along ``motion`` by ``method`` (built from
    ``timing.method`` and its options by the caller), sampled as ``sampling`` says, keeping
    ``clearance`` (m) from ``obstacles`` (world frame), within ``deadline``.

    Raises:
        InvalidRequest: malformed or conflicting input (the message names the field).
    """
    kinds = check_constraint_kinds(timing.constraints, method)
    check_timing(timing, sampling.dt)
    check_obstacles(obstacles)
    _check_sampling(sampling, timing)
    _check_grid(timing, method, robot)
    margin = timing.limit_margin
    if not (np.isfinite(margin) and 0.0 <= margin <= MAX_LIMIT_MARGIN):
        raise InvalidRequest(f"timing.limit_margin must lie in [0, {MAX_LIMIT_MARGIN}], got {margin}")
    limits = _limits(robot, motion, method, timing)
    limits = limits.tightened(margin) if margin else limits
    notes: tuple[str, ...] = ()
    if isinstance(motion, WaypointPath):
        motion, turns = continuous_turns(robot, motion)
        motion, dropped = without_repeats(motion)
        notes = (*turns, *dropped)
    _check_method_serves(method, motion, obstacles, robot, timing, kinds, limits)
    return Problem(
        robot=robot, motion=motion, method=method, options=timing, kinds=kinds, limits=limits, margin=margin,
        threshold=gate_threshold(margin), sampling=sampling, obstacles=tuple(obstacles), clearance=clearance,
        deadline=deadline, notes=notes,
    )


def _check_sampling(sampling: Sampling, timing: Timing) -> None:
    """Samples on whole periods slow the motion uniformly: not with moving boundary states."""
    if sampling.exact_period and any(
        v is not None and np.any(np.asarray(v) != 0.0) for v in (timing.start_velocity, timing.end_velocity)
    ):
        raise InvalidRequest(
            "output.exact_period slows the motion uniformly, which would change the nonzero "
            "timing.boundary velocities: set output.exact_period to false (samples every dt "
            "plus the final instant) or plan from and to rest"
        )


def _check_grid(timing: Timing, method: TimingMethod | MotionGenerator, robot: Robot) -> None:
    """The grid asked for, within the grid's range and the method's memory on this robot."""
    if timing.grid_points is not None and not 2 <= timing.grid_points <= MAX_POINTS:
        raise InvalidRequest(f"timing.grid_points must lie in [2, {MAX_POINTS}], got {timing.grid_points}")
    if timing.grid_points is not None and timing.grid_points > method.max_grid_intervals(robot.dof):
        raise InvalidRequest(
            f"timing.grid_points = {timing.grid_points} is more than {method.name} serves on a "
            f"{robot.dof}-joint robot (its memory grows with grid intervals times joints): use "
            f"timing.grid_points <= {method.max_grid_intervals(robot.dof)}"
        )


def _limits(robot: Robot, motion: MotionSpec, method: TimingMethod | MotionGenerator, timing: Timing) -> JointLimits:
    """The robot's limits with the overrides and scales asked for, and the tool-speed limit."""
    check_scaled_limits(robot.limits.with_request(timing.limit_overrides), timing.limit_scales, robot.joint_names)
    limits: JointLimits = robot.limits.with_request(timing.limit_overrides, timing.limit_scales)
    tool = tool_speed_limit(robot, timing.tool_frame, timing.tool_speed, timing.tool_angular_speed)
    if tool is None:
        return limits
    _check_tool_limit_served(motion, method)
    return dataclasses.replace(limits, tool=tool)


def _check_tool_limit_served(motion: MotionSpec, method: TimingMethod | MotionGenerator) -> None:
    """Tool-speed limits bound the path speed of a given path: refuse them where the path is
    shaped by the timing (free motions, via points)."""
    if isinstance(motion, FreeMotion) or method.name == "collocation":
        raise InvalidRequest(
            "timing.limits.tool_speed and tool_angular_speed are not served by collocation on a free path; "
            "give the path (waypoints or a cartesian line) and a method such as phase_plane"
        )
    if isinstance(motion, WaypointPath) and motion.interpolation == "via":
        raise InvalidRequest(
            "timing.limits.tool_speed and tool_angular_speed are not served with interpolation 'via' "
            "(its segments are shaped by their time laws); use 'spline' or 'linear'"
        )


def _check_method_serves(method, motion: MotionSpec, obstacles, robot: Robot, timing: Timing, kinds, limits: JointLimits) -> None:
    """The method against the motion: state-to-state methods take two waypoints, a free motion
    needs a generator that finds its path, obstacles on a free path need the search."""
    if method.two_waypoints_only and (not isinstance(motion, WaypointPath) or len(motion.waypoints) != 2):
        given = f"{len(motion.waypoints)} waypoints" if isinstance(motion, WaypointPath) else "a cartesian path"
        raise InvalidRequest(
            f"timing.method {method.name!r} plans state-to-state motions: give exactly 2 waypoints, not "
            f"{given} (the offline library has no intermediate waypoints); use phase_plane or a time "
            "law through several waypoints"
        )
    if obstacles and isinstance(motion, FreeMotion) and method.name != "search":
        raise InvalidRequest(
            "path.obstacles on a free path are served by timing.method 'search' (the global search among obstacles); "
            "collocation does not see obstacles"
        )
    if isinstance(method, MotionGenerator):
        method.validate(robot, motion, timing, kinds, limits)
    elif isinstance(motion, FreeMotion):
        raise InvalidRequest(
            "a free path (start and goal only) needs timing.method 'collocation' or 'search', and collocation a free path"
        )
