"""Timing a given path: each stretch between corners through the limit gate, via points, and
joints moving on their own; the grid, the boundary and the checks every one of them shares.

A ``Timed`` is what ``toptraj.planners.plan`` turns into the answer: the path, its timing, its stretches
as they were timed and checked, and what to tell about it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from toptraj.planners.checks.gate import TimedStretch, checked, gated
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.constraints.zones import on_stretch, with_edges
from toptraj.planners.errors import InfeasiblePath, InvalidRequest
from toptraj.planners.generators.unsynchronized import unsynchronized_trajectory
from toptraj.planners.generators.via_points import via_point_trajectory
from toptraj.planners.paths import GeometricPath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.paths.stretch import Stretch, stretches
from toptraj.planners.problem.boundary import path_acceleration, path_speed
from toptraj.planners.problem.requests import Timing, WaypointPath
from toptraj.planners.problem.waypoints import checked_waypoints
from toptraj.planners.timing.base import Boundary, PathTiming, TimingMethod
from toptraj.planners.timing.segmented import SegmentedTiming
from toptraj.robots import Robot


def check_path_within_limits(robot: Robot, path: GeometricPath, s: np.ndarray) -> None:
    """Splines may overshoot between waypoints: refuse a path that leaves the joint range (where
    it lies farthest outside on a spline; elsewhere, the first of 4 points per interval of the
    grid ``s`` that does)."""
    lower, upper = robot.limits.position_lower, robot.limits.position_upper
    outside = path.outside_range(lower, upper, 4 * len(s) + 1)
    if outside is not None:
        at, joint, value = outside
        raise InfeasiblePath(
            f"the interpolated path leaves the range [{lower[joint]:.6g}, {upper[joint]:.6g}] of joint "
            f"{robot.joint_names[joint]!r} at s = {at:.4f} (q = {value:.6g}); "
            "add waypoints or use interpolation 'linear'",
            s=at,
            joint=robot.joint_names[joint],
        )


def check_jerk_finite(path: GeometricPath, kinds) -> None:
    """A jerk limit needs a path whose d2q/ds2 is continuous where the motion goes on: at a
    break (a straight segment meeting a circular blend) the joint acceleration q'' sd^2 jumps
    unless the motion stops there, an infinite jerk."""
    if "jerk" not in kinds or not len(path.breaks):
        return
    s = float(path.breaks[0])
    raise InfeasiblePath(
        f"the path's curvature d2q/ds2 jumps at s = {s:.4f} (where a straight segment meets a blend), "
        "so the joint accelerations jump there and no motion that passes it has a finite jerk: use "
        "interpolation 'spline' with a jerk limit, or leave 'jerk' out of timing.constraints",
        s=s,
        limit="jerk",
    )


def moving_velocity(velocity):
    """A boundary velocity, or ``None`` for rest (a zero vector included)."""
    if velocity is None or not np.any(np.asarray(velocity) != 0.0):
        return None
    return velocity


def path_boundary(path: GeometricPath, timing: Timing, method: TimingMethod) -> Boundary:
    if (timing.start_acceleration is not None or timing.end_acceleration is not None) and not method.takes_acceleration_boundary:
        raise InvalidRequest(
            f"timing.boundary accelerations are not used by timing.method {method.name!r}; use quintic"
        )
    if timing.duration is not None and not method.takes_duration:
        raise InvalidRequest(
            f"timing.duration is not used by timing.method {method.name!r}, which finds the shortest "
            "duration itself; leave it out or use a time law"
        )
    sd_start = path_speed(path, timing.start_velocity, 0.0, "timing.boundary.start_velocity")
    sd_end = path_speed(path, timing.end_velocity, 1.0, "timing.boundary.end_velocity")
    return Boundary(
        sd_start=sd_start,
        sd_end=sd_end,
        sdd_start=path_acceleration(path, timing.start_acceleration, sd_start, 0.0, "timing.boundary.start_acceleration"),
        sdd_end=path_acceleration(path, timing.end_acceleration, sd_end, 1.0, "timing.boundary.end_acceleration"),
    )


class Timed(NamedTuple):
    """A path with its timing, its stretches as they were timed and checked, and what to tell
    about it."""

    path: GeometricPath
    timing: PathTiming
    stretches: tuple[TimedStretch, ...]
    method: str
    notes: tuple[str, ...] = ()
    cost: float | None = None
    solver: dict | None = None
    search: dict | None = None
    switching_times: dict | None = None
    #: For a method that finds the motion itself (a free path): the estimated relative gap of
    #: its objective to the optimum of its own problem, and how it was estimated; ``None`` when
    #: the answer's accuracy is that of its path's timing (``toptraj.planners.runner.accuracy``).
    motion_gap: tuple[float | None, str] | None = None


def timing_grid(path: GeometricPath, n_intervals: int | None, method: TimingMethod, robot: Robot, s: np.ndarray | None = None) -> np.ndarray:
    """The grid of ``path`` (``n_intervals``, else the default; ``s``: that grid, already
    built), within what ``method`` serves on ``robot``: a long path's default grid is thinned to
    ``method.max_grid_intervals``."""
    s = path_grid(path, n_intervals) if s is None else s
    cap = method.max_grid_intervals(robot.dof)
    return s if len(s) - 1 <= cap else path_grid(path, cap)


def _stretch_boundary(boundary: Boundary, width: float, first: bool, last: bool) -> Boundary:
    """The boundary of one stretch in its own parameter (sigma-dot = s-dot / w): the path's
    boundary at the path's ends, rest at its corners."""
    def scaled(value):
        return None if value is None else value / width

    return Boundary(
        sd_start=boundary.sd_start / width if first else 0.0,
        sd_end=boundary.sd_end / width if last else 0.0,
        sdd_start=scaled(boundary.sdd_start) if first else None,
        sdd_end=scaled(boundary.sdd_end) if last else None,
    )


def _time_stretch(robot, stretch, method, grid_points, kinds, limits, boundary, duration, threshold, deadline, grid=None):
    if isinstance(stretch, Stretch):  # the zones in the stretch's own parameter
        limits = on_stretch(limits, stretch.start, stretch.width)
    s = timing_grid(stretch, grid_points, method, robot, grid)
    if limits.zones:
        s = with_edges(s, limits.zones, stretch.knots)
    deadline.progress(0.0, "constraints")
    constraints = build_path_constraints(stretch, robot, limits, kinds, s, deadline)
    deadline.check()
    timing, constraints, check = gated(
        robot, stretch, method, constraints, boundary, duration, kinds, limits, threshold, deadline.within(0.3, 1.0),
        grid_given=grid_points is not None,
    )
    return TimedStretch(stretch, timing, constraints, check)


def timed_path(robot, path, method, timing, kinds, limits, deadline, threshold) -> Timed:
    """A given path timed by ``method``; each stretch between corners (where the motion stops)
    on its own, as its own rest-to-rest problem, and every one through the limit gate."""
    grid = path_grid(path, timing.grid_points)
    check_path_within_limits(robot, path, grid)
    check_jerk_finite(path, kinds)
    boundary = path_boundary(path, timing, method)
    parts = stretches(path)
    widths = [getattr(part, "width", 1.0) for part in parts]
    counts = [None if timing.grid_points is None else max(1, round(timing.grid_points * w)) for w in widths]
    boundaries = [
        _stretch_boundary(boundary, w, k == 0, k == len(parts) - 1) if len(parts) > 1 else boundary
        for k, w in enumerate(widths)
    ]
    durations = [None] * len(parts)
    if timing.duration is not None and len(parts) > 1:
        shortest = [
            method.solve(build_path_constraints(part, robot, limits, kinds, path_grid(part, n), deadline), b, None, deadline).duration
            for part, n, b in zip(parts, counts, boundaries)
        ]
        durations = [timing.duration * T / sum(shortest) for T in shortest]
    elif timing.duration is not None:
        durations = [timing.duration]
    shares = [deadline.within(k / len(parts), (k + 1) / len(parts)) for k in range(len(parts))]
    timed = [
        _time_stretch(robot, part, method, n, kinds, limits, b, T, threshold, share, grid if part is path else None)
        for part, n, b, T, share in zip(parts, counts, boundaries, durations, shares)
    ]
    if len(timed) == 1:
        result = timed[0].timing
    else:
        ends = [part.end for part in parts if isinstance(part, Stretch)]
        assert len(ends) == len(parts)  # a path with corners comes apart into stretches
        edges = np.concatenate(([0.0], ends))
        result = SegmentedTiming(edges, tuple(item.timing for item in timed))
    return Timed(path, result, tuple(timed), method.name, cost=getattr(result, "cost", None))


def timed_via_points(robot, spec, method, timing, kinds, limits, deadline, threshold) -> Timed:
    """Via points: segments shaped and timed together by the limits."""
    if timing.start_velocity is not None or timing.end_velocity is not None:
        raise InvalidRequest("via-point trajectories start and end at rest: leave timing.boundary out")
    if timing.supporting_points is not None:
        raise InvalidRequest("via-point segments are polynomials: leave timing.supporting_points out, or use 'spline' or 'linear'")
    if "jerk" in kinds and method.name in ("cubic", "quintic"):
        method.refuse_jerk_limit()
    path, result = via_point_trajectory(robot, checked_waypoints(robot, spec), method.name, limits, kinds, timing.duration, deadline)
    s = timing_grid(path, timing.grid_points, method, robot)
    check_path_within_limits(robot, path, s)
    constraints = build_path_constraints(path, robot, limits, tuple(k for k in kinds if k != "jerk"), s, deadline)
    stretch = checked(robot, path, result, method.name, kinds, limits, threshold, constraints)
    return Timed(path, result, (stretch,), method.name)


def timed_unsynchronized(robot, spec, method, timing, kinds, limits, deadline, threshold) -> Timed:
    """Every joint at its own full speed to its goal (``timing.synchronization = "none"``)."""
    if not isinstance(spec, WaypointPath) or spec.interpolation == "via" or len(spec.waypoints) != 2:
        raise InvalidRequest(
            "timing.synchronization 'none' moves every joint on its own from a start to a goal: give "
            "exactly 2 waypoints (interpolation 'spline' or 'linear'), or use 'normalized'"
        )
    boundary = (timing.start_velocity, timing.end_velocity, timing.start_acceleration, timing.end_acceleration)
    if any(value is not None for value in boundary) or limits.tool is not None:
        raise InvalidRequest(
            "timing.synchronization 'none' moves every joint from rest to rest on its own: leave "
            "timing.boundary and the tool-speed limits out, or use 'normalized'"
        )
    if "jerk" in kinds:
        method.refuse_jerk_limit()
    waypoints = checked_waypoints(robot, spec)
    path, result = unsynchronized_trajectory(
        robot, waypoints[0], waypoints[1], method.profile, limits, kinds, timing.duration, deadline
    )
    s = timing_grid(path, timing.grid_points, method, robot)
    check_path_within_limits(robot, path, s)
    constraints = build_path_constraints(path, robot, limits, tuple(k for k in kinds if k != "jerk"), s, deadline)
    stretch = checked(robot, path, result, method.name, kinds, limits, threshold, constraints)
    return Timed(path, result, (stretch,), method.name)
