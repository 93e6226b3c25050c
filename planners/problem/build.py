"""``build_problem``: a robot, a motion, the method that moves it (built by the caller with its
options: a timing method or a motion generator) and the options of the problem (limits asked
for, boundary states, duration, grid, sampling, obstacles, deadline), validated once into a
``Problem`` (``toptraj.planners.problem.problem``).

The checks, in order: a time law's spline against the boundary, the constraint kinds against
what the method serves, ranges of the numbers and the obstacles, sampling against the boundary,
the grid against the method's memory, the margin, the limits with their overrides and scales,
the tool-speed limit, the waypoints (repeats dropped, continuous joints' turns), the method
against the motion (two waypoints only; what a generator serves). The rules among one option
object's own fields are its constructor's (``toptraj.planners.problem.time_law.TimeLaw``). What can only
be known from the path (its joint range, its boundary tangents) is checked where the path is
built.
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
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.planners.problem.bounded import check_speed_bounded
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.gravity_notes import gravity_notes
from toptraj.planners.problem.methods import MotionGenerator
from toptraj.planners.problem.problem import AT_REST, BoundaryStates, LimitRequest, MotionSpec, Problem, Sampling
from toptraj.planners.problem.raised_limits import raised_limits
from toptraj.planners.problem.ranges import check_numbers, check_scaled_limits
from toptraj.planners.problem.requests import WaypointPath, check_constraint_kinds, default_kinds
from toptraj.planners.problem.waypoints import checked_waypoints, continuous_turns, repeated_points, without_repeats
from toptraj.planners.problem.zones import check_zones, check_zones_held, check_zones_served
from toptraj.planners.timing.base import TimingMethod
from toptraj.robots import JointLimits, Robot, ToolSpeedLimit

#: Largest limit margin (a fraction of every limit kept in reserve).
MAX_LIMIT_MARGIN = 0.5
#: Distance (m) every link keeps from the obstacles unless a request says otherwise.
DEFAULT_CLEARANCE = 0.01


def build_problem(
    robot: Robot,
    motion: MotionSpec,
    method: TimingMethod | MotionGenerator,
    *,
    limits: LimitRequest = LimitRequest(),
    boundary: BoundaryStates = AT_REST,
    duration: float | None = None,
    grid: int | None = None,
    sampling: Sampling = Sampling(),
    obstacles: tuple[Obstacle, ...] = (),
    clearance: float = DEFAULT_CLEARANCE,
    deadline: Deadline = NO_DEADLINE,
    self_collision: bool = False,
) -> Problem:
    """The validated problem of moving ``robot`` along ``motion`` by ``method`` (a timing method
    or a motion generator, holding its options) under ``limits``, between the ``boundary``
    states, in ``duration`` seconds (``None``: the shortest) on ``grid`` intervals (``None``:
    from the path), sampled as ``sampling`` says, keeping ``clearance`` (m) from ``obstacles``
    (world frame), within ``deadline``.

    Raises:
        InvalidRequest: malformed or conflicting input (the error names the field).
        InfeasiblePath, SelfCollision: a motion generator's own checks (``validate``), e.g. a
            searched free path's start or goal too close to an obstacle or folded on itself.
    """
    if method.supporting_points is not None and boundary.moving:
        raise Conflicting("law.supporting_points", method.supporting_points, ("boundary",), rule="law_from_rest")
    unheld: tuple[str, ...] = ()
    if limits.kinds is None:
        asked, unheld = default_kinds(method)
        kinds = check_constraint_kinds(asked, method)
    else:
        kinds = check_constraint_kinds(limits.kinds, method)
    check_numbers(limits, boundary, duration, sampling.dt)
    check_obstacles(obstacles)
    if sampling.exact_period and boundary.velocities_moving:
        raise Conflicting("sampling.exact_period", sampling.exact_period, ("boundary",), rule="exact_period_with_moving_ends")
    _check_grid(grid, method, robot)
    margin = limits.margin
    if not (np.isfinite(margin) and 0.0 <= margin <= MAX_LIMIT_MARGIN):
        raise OutOfRange("limits.margin", margin, 0.0, MAX_LIMIT_MARGIN, rule="margin_out_of_range")
    held = _limits(robot, motion, method, limits)  # zones checked and refused where not served
    check_zones_held(limits.zones, kinds)
    held = held.tightened(margin) if margin else held
    motion, told = _prepared(robot, motion)
    notes: tuple[str, ...] = (*raised_limits(robot, limits, kinds), *gravity_notes(robot), *told)
    check_speed_bounded(robot, held, kinds, served=method.kinds)
    problem = Problem(
        robot=robot, motion=motion, method=method, requested=limits, grid=grid, boundary=boundary, duration=duration,
        kinds=kinds, limits=held, margin=margin, threshold=gate_threshold(margin), sampling=sampling,
        obstacles=tuple(obstacles), clearance=clearance, deadline=deadline, notes=notes, self_collision=self_collision,
        unheld=unheld,
    )
    _check_method_serves(problem)
    return problem


def _prepared(robot: Robot, motion: MotionSpec) -> tuple[MotionSpec, tuple[str, ...]]:
    """``motion`` as it is planned (joint waypoints checked, then turned the short way as asked
    and their repeats dropped), and the notes that say what changed."""
    if isinstance(motion, WaypointPath):
        checked_waypoints(robot, motion)  # before any is dropped: refusals name the waypoints as given
        motion, turns = continuous_turns(robot, motion)
        motion, dropped = without_repeats(motion)
        return motion, (*turns, *dropped)
    if isinstance(motion, CartesianLine):
        return motion, repeated_points(motion)
    return motion, ()


def _check_grid(grid: int | None, method: TimingMethod | MotionGenerator, robot: Robot) -> None:
    """The grid asked for, within the grid's range and the method's memory on this robot."""
    if grid is not None and not 2 <= grid <= MAX_POINTS:
        raise OutOfRange("grid.intervals", grid, 2, MAX_POINTS, rule="grid_out_of_range")


def _limits(robot: Robot, motion: MotionSpec, method: TimingMethod | MotionGenerator, asked: LimitRequest) -> JointLimits:
    """The robot's limits with the overrides and scales asked for, and the tool-speed limit."""
    check_scaled_limits(robot.limits.with_request(asked.overrides), asked.scales, robot.joint_names)
    limits: JointLimits = robot.limits.with_request(asked.overrides, asked.scales)
    tool = _tool_limit(robot, motion, method, asked)
    if tool is None:
        return limits
    _check_tool_limit_served(motion, method)
    return dataclasses.replace(limits, tool=tool)


def _tool_limit(robot: Robot, motion: MotionSpec, method: TimingMethod | MotionGenerator, asked: LimitRequest) -> ToolSpeedLimit | None:
    """The tool limit asked for. With zones (checked, and refused where not served) that limit
    the tool's speed, or a tool frame named for the zones' regions, the tool frame's limit even
    without a speed of its own."""
    if not asked.zones:
        return tool_speed_limit(robot, asked.tool_frame, asked.tool_speed, asked.tool_angular_speed)
    check_zones(asked.zones)
    given = not isinstance(motion, FreeMotion) and not isinstance(method, MotionGenerator) and not (
        isinstance(motion, WaypointPath) and motion.interpolation == "via"
    )
    check_zones_served(method.name, given)
    unset = asked.tool_speed is None and asked.tool_angular_speed is None
    framed = asked.tool_frame is not None or any(zone.tool_speed is not None for zone in asked.zones)
    speed = math.inf if unset and framed else asked.tool_speed
    return tool_speed_limit(robot, asked.tool_frame, speed, asked.tool_angular_speed)


def _check_tool_limit_served(motion: MotionSpec, method: TimingMethod | MotionGenerator) -> None:
    """Tool-speed limits bound the path speed of a given path: refuse them where the path is
    shaped by the timing (free motions, via points)."""
    if isinstance(motion, FreeMotion) or method.name == "collocation":
        raise NotServed("limits.tool_speed", None, method.name, rule="tool_speed_on_free_path", alternatives=("phase_plane",))
    if isinstance(motion, WaypointPath) and motion.interpolation == "via":
        raise NotServed("limits.tool_speed", None, method.name, rule="tool_speed_through_via", alternatives=("spline", "linear"))


def _check_method_serves(problem: Problem) -> None:
    """The method against the motion: state-to-state methods take two waypoints, a free motion
    needs a generator that finds its path, obstacles on a free path need the search."""
    method, motion = problem.method, problem.motion
    if method.two_waypoints_only and (not isinstance(motion, WaypointPath) or len(motion.waypoints) != 2):
        count = len(motion.waypoints) if isinstance(motion, WaypointPath) else None
        raise NotServed("waypoints", count, method.name, rule="needs_two_waypoints", alternatives=("phase_plane",))
    if problem.obstacles and isinstance(motion, FreeMotion) and method.name != "search":
        raise NotServed("obstacles", len(problem.obstacles), method.name, rule="obstacles_need_search", alternatives=("search",))
    if isinstance(motion, WaypointPath) and motion.interpolation == "via" and not isinstance(method, MotionGenerator):
        raise NotServed("interpolation", "via", method.name, rule="via_points_need_their_generator", alternatives=("cubic", "quintic"))
    if isinstance(method, MotionGenerator):
        method.validate(problem)
    elif isinstance(motion, FreeMotion):
        raise NotServed("method", method.name, method.name, rule="free_path_needs_collocation", alternatives=("collocation", "search"))
