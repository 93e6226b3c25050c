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
import math

import numpy as np

from toptraj.planners.checks.gate import gate_threshold
from toptraj.planners.collision import Obstacle
from toptraj.planners.collision.obstacles import check_obstacles
from toptraj.planners.constraints.tool_speed import tool_speed_limit
from toptraj.planners.errors import Conflicting, NotServed, OutOfRange
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import MotionGenerator
from toptraj.planners.problem.problem import MotionSpec, Problem, Sampling
from toptraj.planners.problem.ranges import check_scaled_limits, check_timing
from toptraj.planners.problem.requests import Timing, WaypointPath, check_constraint_kinds
from toptraj.planners.problem.waypoints import continuous_turns, without_repeats
from toptraj.planners.problem.zones import check_zones, check_zones_served
from toptraj.planners.timing.base import TimingMethod
from toptraj.robots import JointLimits, Robot, ToolSpeedLimit

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
    self_collision: bool = False,
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
        raise OutOfRange("limits.margin", margin, 0.0, MAX_LIMIT_MARGIN, rule="margin_out_of_range")
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
        deadline=deadline, notes=notes, self_collision=self_collision,
    )


def _check_sampling(sampling: Sampling, timing: Timing) -> None:
    """Samples on whole periods slow the motion uniformly: not with moving boundary states."""
    if sampling.exact_period and any(
        v is not None and np.any(np.asarray(v) != 0.0) for v in (timing.start_velocity, timing.end_velocity)
    ):
        raise Conflicting("sampling.exact_period", sampling.exact_period, ("boundary",), rule="exact_period_with_moving_ends")


def _check_grid(timing: Timing, method: TimingMethod | MotionGenerator, robot: Robot) -> None:
    """The grid asked for, within the grid's range and the method's memory on this robot."""
    if timing.grid_points is not None and not 2 <= timing.grid_points <= MAX_POINTS:
        raise OutOfRange("grid.intervals", timing.grid_points, 2, MAX_POINTS, rule="grid_out_of_range")


def _limits(robot: Robot, motion: MotionSpec, method: TimingMethod | MotionGenerator, timing: Timing) -> JointLimits:
    """The robot's limits with the overrides and scales asked for, and the tool-speed limit."""
    check_scaled_limits(robot.limits.with_request(timing.limit_overrides), timing.limit_scales, robot.joint_names)
    limits: JointLimits = robot.limits.with_request(timing.limit_overrides, timing.limit_scales)
    tool = _tool_limit(robot, motion, method, timing)
    if tool is None:
        return limits
    _check_tool_limit_served(motion, method)
    return dataclasses.replace(limits, tool=tool)


def _tool_limit(robot: Robot, motion: MotionSpec, method: TimingMethod | MotionGenerator, timing: Timing) -> ToolSpeedLimit | None:
    """The request's tool limit. With zones (checked, and refused where not served) that limit
    the tool's speed, or a tool frame named for the zones' regions, the tool frame's limit even
    without a speed of its own."""
    if not timing.zones:
        return tool_speed_limit(robot, timing.tool_frame, timing.tool_speed, timing.tool_angular_speed)
    check_zones(timing.zones)
    given = not isinstance(motion, FreeMotion) and timing.synchronization != "none" and not (
        isinstance(motion, WaypointPath) and motion.interpolation == "via"
    )
    check_zones_served(method.name, given)
    unset = timing.tool_speed is None and timing.tool_angular_speed is None
    framed = timing.tool_frame is not None or any(zone.tool_speed is not None for zone in timing.zones)
    speed = math.inf if unset and framed else timing.tool_speed
    return tool_speed_limit(robot, timing.tool_frame, speed, timing.tool_angular_speed)


def _check_tool_limit_served(motion: MotionSpec, method: TimingMethod | MotionGenerator) -> None:
    """Tool-speed limits bound the path speed of a given path: refuse them where the path is
    shaped by the timing (free motions, via points)."""
    if isinstance(motion, FreeMotion) or method.name == "collocation":
        raise NotServed("limits.tool_speed", None, method.name, rule="tool_speed_on_free_path", alternatives=("phase_plane",))
    if isinstance(motion, WaypointPath) and motion.interpolation == "via":
        raise NotServed("limits.tool_speed", None, method.name, rule="tool_speed_through_via", alternatives=("spline", "linear"))


def _check_method_serves(method, motion: MotionSpec, obstacles, robot: Robot, timing: Timing, kinds, limits: JointLimits) -> None:
    """The method against the motion: state-to-state methods take two waypoints, a free motion
    needs a generator that finds its path, obstacles on a free path need the search."""
    if method.two_waypoints_only and (not isinstance(motion, WaypointPath) or len(motion.waypoints) != 2):
        count = len(motion.waypoints) if isinstance(motion, WaypointPath) else None
        raise NotServed("waypoints", count, method.name, rule="needs_two_waypoints", alternatives=("phase_plane",))
    if obstacles and isinstance(motion, FreeMotion) and method.name != "search":
        raise NotServed("obstacles", len(obstacles), method.name, rule="obstacles_need_search", alternatives=("search",))
    if isinstance(method, MotionGenerator):
        method.validate(robot, motion, timing, kinds, limits)
    elif isinstance(motion, FreeMotion):
        raise NotServed("method", method.name, method.name, rule="free_path_needs_collocation", alternatives=("collocation", "search"))
