"""``plan``: from a robot and a motion request to a timed trajectory with torques.

Data flow (DESIGN.md): request -> GeometricPath q(s) -> PathConstraints on a grid (once) ->
timing method -> TimeScaling s(t) -> samples, phase plane and peak utilization.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import NamedTuple

import numpy as np

from planners.boundary import path_acceleration, path_speed
from planners.collision import Obstacle, check_clearance
from planners.constraints import build_path_constraints
from planners.deadline import NO_DEADLINE, Deadline
from planners.errors import InfeasiblePath, InvalidRequest, TimingFailed, numerical_breakdown_is_failure
from planners.free_path import FreeMotion, collocation_path, optimize_motion
from planners.free_path.switching import collocation_switches, refine_collocation, switched_path, switching_times
from planners.gate import TimedStretch, checked, gate_threshold, gated, samples_exceed
from planners.grid import MAX_POINTS, path_grid
from planners.kinematics.conditioning import NEAR_SINGULAR_KAPPA, conditioning_along
from planners.mvc import admissible_set
from planners.paths import GeometricPath
from planners.paths.cartesian import CartesianLine
from planners.paths.stretch import Stretch, stretches
from planners.ranges import check_timing
from planners.requests import Timing, WaypointPath, check_constraint_kinds, timing_method
from planners.results import Conditioning, PhasePlane, PlannedTrajectory, require_finite
from planners.search.curve import GridSplinePath
from planners.search.local import LocalOptimum, optimize_locally
from planners.search.method import global_search
from planners.timing.base import Boundary, PathTiming, TimingMethod
from planners.timing.min_cost import MinCostMethod
from planners.timing.phase_plane import PhasePlaneMethod
from planners.timing.segmented import SegmentedTiming
from planners.timing.unsynchronized import unsynchronized_trajectory
from planners.tool_speed import tool_speed_limit
from planners.trajectory import sample_trajectory
from planners.via_points import via_point_trajectory
from planners.waypoint_checks import checked_waypoints, continuous_turns, make_path, without_repeats
from robots import JointLimits, Robot

MAX_SAMPLES = 200_000
#: Largest number of phase-plane points returned (the grid is thinned evenly beyond it).
MAX_PHASE_PLANE_POINTS = 2_000
#: Share of its limit beyond which a sampled torque counts as saturated when switching times
#: are read off the samples.
SATURATION_READ = 0.98
#: Largest timing.limit_margin (a fraction of every limit kept in reserve).
MAX_LIMIT_MARGIN = 0.5


def _check_path_within_limits(robot: Robot, path: GeometricPath, s: np.ndarray) -> None:
    """Splines may overshoot between waypoints: refuse a path that leaves the joint range."""
    dense = np.linspace(0.0, 1.0, 4 * len(s) + 1)
    q = path(dense)
    lower, upper = robot.limits.position_lower, robot.limits.position_upper
    outside = robot.outside_position_limits(q)
    if outside is not None:
        index, joint = outside
        raise InfeasiblePath(
            f"the interpolated path leaves the range [{lower[joint]:.6g}, {upper[joint]:.6g}] of joint "
            f"{robot.joint_names[joint]!r} at s = {dense[index]:.4f} (q = {q[index, joint]:.6g}); "
            "add waypoints or use interpolation 'linear'",
            s=float(dense[index]),
            joint=robot.joint_names[joint],
        )


def _check_jerk_finite(path: GeometricPath, kinds) -> None:
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


def _moving(velocity):
    """A boundary velocity, or ``None`` for rest (a zero vector included)."""
    if velocity is None or not np.any(np.asarray(velocity) != 0.0):
        return None
    return velocity


def _free_motion(robot, path_spec, method, timing: Timing, limits, deadline):
    """Path and timing optimized together (``path.kind = "free"`` with ``collocation``)."""
    if not isinstance(path_spec, FreeMotion) or method.name != "collocation":
        raise InvalidRequest(
            "a free path (start and goal only) needs timing.method 'collocation' or 'search', and collocation a free path"
        )
    if timing.grid_points is not None and not 4 <= timing.grid_points <= 100:
        raise InvalidRequest(f"timing.grid_points sets the collocation intervals, 4 to 100; got {timing.grid_points}")
    if timing.grid_points is not None:
        path_spec = dataclasses.replace(path_spec, intervals=timing.grid_points)
    unlimited = np.full(robot.dof, np.inf)
    limits = dataclasses.replace(
        limits,
        velocity=limits.velocity if "velocity" in timing.constraints else unlimited,
        acceleration=limits.acceleration if "acceleration" in timing.constraints else unlimited,
    )
    result = optimize_motion(robot, limits, path_spec, timing.torque_weight, deadline)
    path, timed = collocation_path(result)
    solver = {
        "cost": result.cost,
        "duration": float(result.t[-1]),
        "status": result.status,
        "iterations": result.iterations,
        "initial_guess": result.initial_guess,
        "solve_s": result.solve_s,
    }
    return path, solver, timed, result


def _check_tool_limit_served(path_spec, method: TimingMethod) -> None:
    """Tool-speed limits bound the path speed of a given path: refuse them where the path is
    shaped by the timing (free motions, via points)."""
    if isinstance(path_spec, FreeMotion) or method.name == "collocation":
        raise InvalidRequest(
            "timing.limits.tool_speed and tool_angular_speed are not served by collocation on a free path; "
            "give the path (waypoints or a cartesian line) and a method such as phase_plane"
        )
    if isinstance(path_spec, WaypointPath) and path_spec.interpolation == "via":
        raise InvalidRequest(
            "timing.limits.tool_speed and tool_angular_speed are not served with interpolation 'via' "
            "(its segments are shaped by their time laws); use 'spline' or 'linear'"
        )


def _boundary(path: GeometricPath, timing: Timing, method: TimingMethod) -> Boundary:
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


class _Timed(NamedTuple):
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


def _grid(path: GeometricPath, n_intervals: int | None, method: TimingMethod, robot: Robot) -> np.ndarray:
    """The grid of ``path`` (``n_intervals``, else the default), within what ``method`` serves on
    ``robot``: a long path's default grid is thinned to ``method.max_grid_intervals``."""
    s = path_grid(path, n_intervals)
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


def _time_stretch(robot, stretch, method, grid_points, kinds, limits, boundary, duration, threshold, deadline):
    s = _grid(stretch, grid_points, method, robot)
    deadline.progress(0.0, "constraints")
    constraints = build_path_constraints(stretch, robot, limits, kinds, s, deadline)
    deadline.check()
    timing, constraints, check = gated(
        robot, stretch, method, constraints, boundary, duration, kinds, limits, threshold, deadline.within(0.3, 1.0)
    )
    return TimedStretch(stretch, timing, constraints, check)


def _timed_path(robot, path, method, timing, kinds, limits, deadline, threshold) -> _Timed:
    """A given path timed by ``method``; each stretch between corners (where the motion stops)
    on its own, as its own rest-to-rest problem, and every one through the limit gate."""
    _check_path_within_limits(robot, path, path_grid(path, timing.grid_points))
    _check_jerk_finite(path, kinds)
    boundary = _boundary(path, timing, method)
    parts = stretches(path)
    widths = [getattr(part, "width", 1.0) for part in parts]
    grid = [None if timing.grid_points is None else max(1, round(timing.grid_points * w)) for w in widths]
    boundaries = [
        _stretch_boundary(boundary, w, k == 0, k == len(parts) - 1) if len(parts) > 1 else boundary
        for k, w in enumerate(widths)
    ]
    durations = [None] * len(parts)
    if timing.duration is not None and len(parts) > 1:
        shortest = [
            method.solve(build_path_constraints(part, robot, limits, kinds, path_grid(part, n), deadline), b, None, deadline).duration
            for part, n, b in zip(parts, grid, boundaries)
        ]
        durations = [timing.duration * T / sum(shortest) for T in shortest]
    elif timing.duration is not None:
        durations = [timing.duration]
    shares = [deadline.within(k / len(parts), (k + 1) / len(parts)) for k in range(len(parts))]
    timed = [
        _time_stretch(robot, part, method, n, kinds, limits, b, T, threshold, share)
        for part, n, b, T, share in zip(parts, grid, boundaries, durations, shares)
    ]
    if len(timed) == 1:
        result = timed[0].timing
    else:
        ends = [part.end for part in parts if isinstance(part, Stretch)]
        assert len(ends) == len(parts)  # a path with corners comes apart into stretches
        edges = np.concatenate(([0.0], ends))
        result = SegmentedTiming(edges, tuple(item.timing for item in timed))
    return _Timed(path, result, tuple(timed), method.name, cost=getattr(result, "cost", None))


def _timed_via_points(robot, spec, method, timing, kinds, limits, deadline, threshold) -> _Timed:
    """Via points: segments shaped and timed together by the limits."""
    if timing.start_velocity is not None or timing.end_velocity is not None:
        raise InvalidRequest("via-point trajectories start and end at rest: leave timing.boundary out")
    if timing.supporting_points is not None:
        raise InvalidRequest("via-point segments are polynomials: leave timing.supporting_points out, or use 'spline' or 'linear'")
    if "jerk" in kinds and method.name in ("cubic", "quintic"):
        method.refuse_jerk_limit()
    path, result = via_point_trajectory(robot, checked_waypoints(robot, spec), method.name, limits, kinds, timing.duration, deadline)
    s = _grid(path, timing.grid_points, method, robot)
    _check_path_within_limits(robot, path, s)
    constraints = build_path_constraints(path, robot, limits, tuple(k for k in kinds if k != "jerk"), s, deadline)
    stretch = checked(robot, path, result, method.name, kinds, limits, threshold, constraints)
    return _Timed(path, result, (stretch,), method.name)


def _timed_unsynchronized(robot, spec, method, timing, kinds, limits, deadline, threshold) -> _Timed:
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
    s = _grid(path, timing.grid_points, method, robot)
    _check_path_within_limits(robot, path, s)
    constraints = build_path_constraints(path, robot, limits, tuple(k for k in kinds if k != "jerk"), s, deadline)
    stretch = checked(robot, path, result, method.name, kinds, limits, threshold, constraints)
    return _Timed(path, result, (stretch,), method.name)


def _timed_free_motion(robot, spec, method, timing, kinds, limits, deadline, threshold) -> _Timed:
    """A free motion: the collocation's path, re-timed exactly along itself (phase_plane, or
    min_cost for beta > 0) so that every limit holds between the collocation instants too."""
    path, solver, collocation_timing, collocation = _free_motion(robot, spec, method, timing, limits, deadline.within(0.0, 0.8))
    retiming = deadline.within(0.8, 0.9, "re-timing along the collocation's path")
    retiming.progress(0.0, "constraints")
    retimer = PhasePlaneMethod() if timing.torque_weight == 0.0 else MinCostMethod(timing.torque_weight)
    constraints = build_path_constraints(path, robot, limits, kinds, _grid(path, None, retimer, robot), deadline)
    moving = dataclasses.replace(
        timing, start_velocity=_moving(spec.start_velocity), end_velocity=_moving(spec.end_velocity), duration=None
    )
    notes: tuple[str, ...] = ()
    try:
        result, constraints, check = gated(
            robot, path, retimer, constraints, _boundary(path, moving, retimer), None, kinds, limits, threshold,
            retiming.within(0.1, 1.0),
        )
        stretch = TimedStretch(path, result, constraints, check)
    except InfeasiblePath as error:
        # A boundary state right at a limit may be out of reach of the conservative re-timing;
        # the collocation's own timing is then returned, if it holds the limits.
        result = collocation_timing
        stretch = checked(robot, path, result, "collocation", kinds, limits, threshold, constraints)
        notes = (f"the collocation's own timing is returned (re-timing along its path failed: {error.detail})",)
    switching = None
    if timing.torque_weight == 0.0:
        deadline.progress(0.9, "refining the switching times")
        path, result, stretch, switching, notes = _switched(
            robot, spec, collocation, (path, result, stretch), kinds, limits, threshold, notes, deadline
        )
        solver = {**solver, "switching": "refined" if switching is not None else "read off the samples"}
    cost = getattr(result, "cost", None) if timing.torque_weight else result.duration
    return _Timed(path, result, (stretch,), "collocation", notes, cost, solver, switching_times=switching)


def _switched(robot, spec, collocation, timed, kinds, limits, threshold, notes, deadline):
    """The time-optimal free motion with exact bang-bang torques (``planners.free_path.switching``)
    in place of ``timed`` (path, timing, stretch) when it reaches the goal, is not longer and
    passes the limit gate; with its switching times (else ``None``)."""
    path, result, stretch = timed
    refined = refine_collocation(robot, limits, spec, collocation, deadline)
    if refined is None or refined.duration > result.duration:
        return path, result, stretch, None, notes
    switched, timing = switched_path(refined)
    constraints = build_path_constraints(switched, robot, limits, kinds, path_grid(switched), deadline)
    try:
        stretch = checked(robot, switched, timing, "collocation", kinds, limits, threshold, constraints)
    except InfeasiblePath as error:
        return path, result, stretch, None, (*notes, f"the bang-bang refinement is not returned: {error.detail}")
    return switched, timing, stretch, switching_times(refined.controls, robot.joint_names), notes


def _timed_search(robot, spec, timing, kinds, limits, deadline, threshold, obstacles, clearance) -> _Timed:
    """The global search (``planners.search``, Jeong & Lee section 2): the best grid path of
    each tube, then each one's local optimization (section 2.6) within its share of the budget;
    the fastest optimized path that keeps the clearance is timed by phase_plane through the
    limit gate. The grid path's own curve stands in where its optimization finds nothing."""
    if not isinstance(spec, FreeMotion):
        raise InvalidRequest("timing.method 'search' finds the path itself: give a free path (path.kind 'free', start and goal)")
    if _moving(spec.start_velocity) is not None or _moving(spec.end_velocity) is not None or timing.duration is not None:
        raise InvalidRequest("the search plans the fastest motion from rest to rest: leave timing.boundary and timing.duration out")
    found = global_search(
        robot, limits, kinds, spec.start, spec.goal, timing.search, spec.revolutions, obstacles, clearance, deadline.within(0.0, 0.3)
    )
    tubes = found.result.tubes
    optimized, failures = [], []
    for index, tube in enumerate(tubes):
        remaining = deadline.remaining()
        # the rounds share what is left, three quarters of it (the rest: timing, gate, sampling)
        allowance = None if remaining is None else 0.75 * remaining / (len(tubes) - index)
        part = deadline.within(0.3 + 0.6 * index / len(tubes), 0.3 + 0.6 * (index + 1) / len(tubes))
        part.progress(0.0, f"local optimization of tube {index + 1} of {len(tubes)}")
        try:
            local = optimize_locally(robot, tube.points, limits, kinds, obstacles, clearance, part, allowance_s=allowance)
        except InfeasiblePath as error:
            failures.append(f"tube {index + 1}: {error.detail}")
            continue
        optimized.append((local.duration, index, local))
    plain = dataclasses.replace(timing, method="phase_plane", search=None, start_velocity=None, end_velocity=None)
    candidates: list[tuple[GeometricPath, int, LocalOptimum | None]] = [
        (item.path, index, item) for _, index, item in sorted(optimized, key=lambda item: item[:2])
    ]
    candidates += [(GridSplinePath(tube.points), index, None) for index, tube in enumerate(tubes)]
    for path, index, optimum in candidates:
        try:
            if obstacles:
                check_clearance(path, robot, list(obstacles), clearance, deadline)
            timed = _timed_path(robot, path, PhasePlaneMethod(), plain, kinds, limits, deadline.within(0.9, 1.0), threshold)
        except InfeasiblePath as error:
            failures.append(f"tube {index + 1}{' (optimized)' if optimum is not None else ''}: {error.detail}")
            continue
        end = path.evaluate(np.array([1.0])).q[0]
        turns = [
            f"joint {robot.joint_names[j]!r} ends at {end[j]:.6g} rad, the goal's angle {turn:+.0f} revolution"
            for j in range(robot.dof)
            if (turn := round((end[j] - spec.goal[j]) / (2.0 * np.pi))) != 0
        ]
        notes = [*timed.notes, *turns]
        if optimum is None:
            notes.append("the local optimization found no better path: the best grid path's own curve is returned")
        elif optimum.statistics.stopped == "allowance spent":
            notes.append(
                "the local optimization stopped when its share of the time budget was spent: a job with a larger "
                "budget_s may find a faster path"
            )
        report = found.as_dict(index)
        report["local"] = [_local_report(tubes[i].time, item) for _, i, item in sorted(optimized, key=lambda item: item[1])]
        report["final_time"] = timed.timing.duration
        return timed._replace(method="search", notes=tuple(notes), search=report)
    raise InfeasiblePath("no path the search found could be followed: " + "; ".join(failures))


def _local_report(grid_time: float, local) -> dict:
    """A tube's local optimization for the answer's ``search.local`` (times in s)."""
    stats = local.statistics
    return {
        "grid_time": grid_time,
        "seed_time": stats.seed_duration if np.isfinite(stats.seed_duration) else None,
        "time": local.duration,
        "control_points": [r.control_points for r in stats.rounds],
        "round_times": [r.duration if np.isfinite(r.duration) else None for r in stats.rounds],
        "evaluations": stats.evaluations,
        "stopped": stats.stopped,
        "wall_s": stats.wall_s,
    }


def _phase_plane(stretches_: tuple[TimedStretch, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, sd and the maximum velocity curve (1/s) over the grids the stretches were timed on,
    in the path's own s."""
    pieces = []
    for item in stretches_:
        constraints = item.constraints
        sd = item.timing.speed_at(constraints.s)
        mvc = admissible_set(constraints.linearized(sd**2), constraints.sd_max**2).sd_max
        start, width = getattr(item.stretch, "start", 0.0), getattr(item.stretch, "width", 1.0)
        pieces.append((start + width * constraints.s, width * sd, width * mvc))
    s, sd, mvc = (np.concatenate([piece[i] for piece in pieces]) for i in range(3))
    keep = np.unique(np.linspace(0, len(s) - 1, min(len(s), MAX_PHASE_PLANE_POINTS)).round().astype(int))
    return s[keep], sd[keep], mvc[keep]


def _utilization(stretches_, margin: float) -> dict[str, np.ndarray]:
    """Peak |value| / limit per kind and joint over every stretch, against the limits as
    requested (before any margin)."""
    kinds = stretches_[0].check.utilization.keys()
    return {
        kind: (1.0 - margin) * np.max([item.check.utilization[kind] for item in stretches_], axis=0)
        for kind in kinds
    }


#: Distance (m) every link keeps from the obstacles unless a request says otherwise.
DEFAULT_CLEARANCE = 0.01


def plan(
    robot: Robot,
    path_spec: WaypointPath | CartesianLine | FreeMotion,
    timing: Timing = Timing(),
    dt: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
    max_samples: int = MAX_SAMPLES,
    exact_period: bool = False,
    obstacles: tuple[Obstacle, ...] = (),
    clearance: float = DEFAULT_CLEARANCE,
) -> PlannedTrajectory:
    """Plan the timed trajectory of ``robot`` along ``path_spec``, sampled every ``dt`` seconds
    into at most ``max_samples`` samples. With ``exact_period`` the samples lie on whole periods
    ``dt``, the final state included: the motion is slowed uniformly to end on one
    (``planners.trajectory.sample_trajectory``); ``duration`` stays the planned (optimal) one
    and ``sampled_duration`` is the samples' last instant. With ``obstacles`` (world frame),
    every link keeps ``clearance`` (m) from them along the path (``planners.collision``), and
    the answer carries the smallest distance found.

    Every answer holds the requested limits on a dense resampling within ``LIMIT_TOLERANCE``
    (with ``timing.limit_margin`` > 0, strictly within the limits): the gate refines the grid
    where a limit is exceeded and refuses an answer that still exceeds one.

    Raises:
        InvalidRequest: malformed input (the message names the field), or a ``dt`` that gives
            more than ``max_samples`` samples (the message names the smallest that fits).
        InfeasiblePath: no timing can follow the path within the limits (says where, which
            joint and which limit).
        TimingFailed: the timing method failed.
        BudgetExceeded: ``deadline`` passed.
    """
    started = time.perf_counter()
    method = timing_method(timing)
    kinds = check_constraint_kinds(timing.constraints, method)
    check_timing(timing, dt)
    if exact_period and any(
        v is not None and np.any(np.asarray(v) != 0.0) for v in (timing.start_velocity, timing.end_velocity)
    ):
        raise InvalidRequest(
            "output.exact_period slows the motion uniformly, which would change the nonzero "
            "timing.boundary velocities: set output.exact_period to false (samples every dt "
            "plus the final instant) or plan from and to rest"
        )
    if timing.grid_points is not None and not 2 <= timing.grid_points <= MAX_POINTS:
        raise InvalidRequest(f"timing.grid_points must lie in [2, {MAX_POINTS}], got {timing.grid_points}")
    if timing.grid_points is not None and timing.grid_points > method.max_grid_intervals(robot.dof):
        raise InvalidRequest(
            f"timing.grid_points = {timing.grid_points} is more than {method.name} serves on a "
            f"{robot.dof}-joint robot (its memory grows with grid intervals times joints): use "
            f"timing.grid_points <= {method.max_grid_intervals(robot.dof)}"
        )
    margin = timing.limit_margin
    if not (np.isfinite(margin) and 0.0 <= margin <= MAX_LIMIT_MARGIN):
        raise InvalidRequest(f"timing.limit_margin must lie in [0, {MAX_LIMIT_MARGIN}], got {margin}")
    requested: JointLimits = robot.limits.with_request(timing.limit_overrides, timing.limit_scales)
    tool = tool_speed_limit(robot, timing.tool_frame, timing.tool_speed, timing.tool_angular_speed)
    if tool is not None:
        _check_tool_limit_served(path_spec, method)
        requested = dataclasses.replace(requested, tool=tool)
    limits = requested.tightened(margin) if margin else requested
    threshold = gate_threshold(margin)
    dropped: tuple[str, ...] = ()
    if isinstance(path_spec, WaypointPath):
        path_spec, turns = continuous_turns(robot, path_spec)
        path_spec, dropped = without_repeats(path_spec)
        dropped = (*turns, *dropped)
    if method.two_waypoints_only and (not isinstance(path_spec, WaypointPath) or len(path_spec.waypoints) != 2):
        given = f"{len(path_spec.waypoints)} waypoints" if isinstance(path_spec, WaypointPath) else "a cartesian path"
        raise InvalidRequest(
            f"timing.method {method.name!r} plans state-to-state motions: give exactly 2 waypoints, not "
            f"{given} (the offline library has no intermediate waypoints); use phase_plane or a time "
            "law through several waypoints"
        )
    timing_part = deadline.within(0.0, 0.9)
    checked_first = None
    if obstacles and isinstance(path_spec, FreeMotion) and method.name != "search":
        raise InvalidRequest(
            "path.obstacles on a free path are served by timing.method 'search' (the global search among obstacles); "
            "collocation does not see obstacles"
        )
    with numerical_breakdown_is_failure(method.name):
        if method.name == "search":
            timed = _timed_search(robot, path_spec, timing, kinds, limits, timing_part, threshold, obstacles, clearance)
        elif isinstance(path_spec, FreeMotion) or method.name == "collocation":
            timed = _timed_free_motion(robot, path_spec, method, timing, kinds, limits, timing_part, threshold)
        elif timing.synchronization == "none":
            timing_part.progress(0.0, "joint moves")
            timed = _timed_unsynchronized(robot, path_spec, method, timing, kinds, limits, timing_part, threshold)
        elif isinstance(path_spec, WaypointPath) and path_spec.interpolation == "via":
            timing_part.progress(0.0, "via points")
            timed = _timed_via_points(robot, path_spec, method, timing, kinds, limits, timing_part, threshold)
        else:
            timing_part.progress(0.0, "path")
            path = make_path(robot, path_spec, deadline)
            if obstacles:
                timing_part.progress(0.05, "clearance")
                checked_first = check_clearance(path, robot, list(obstacles), clearance, deadline)
            timed = _timed_path(robot, path, method, timing, kinds, limits, timing_part.within(0.1, 1.0), threshold)
    path, result, notes = timed.path, timed.timing, [*dropped, *timed.notes]
    deadline.check()
    found_clearance = None
    if obstacles:
        # a given path was checked before its timing; a path shaped with its timing (via points) now
        found_clearance = checked_first or check_clearance(path, robot, list(obstacles), clearance, deadline)
    deadline.progress(0.9, "sampling")
    require_finite(timed.method, duration=result.duration)
    if result.duration / dt > max_samples - 2:
        raise InvalidRequest(
            f"output.dt = {dt:g} s gives {math.ceil(result.duration / dt) + 1} samples over the "
            f"{result.duration:.4g} s motion; at most {max_samples} are served: use output.dt >= "
            f"{_round_up(result.duration / (max_samples - 2)):g} s"
        )
    samples = sample_trajectory(path, result, robot, dt, exact_period)
    require_finite(timed.method, samples=[samples.q, samples.qd, samples.qdd, samples.tau])
    beyond = samples_exceed(samples, limits, threshold, kinds, robot, jerk=method.continuous_acceleration)
    if beyond is not None:
        kind, sample, joint = beyond
        what = f"{kind} limit of joint {robot.joint_names[joint]!r}" if joint >= 0 else f"{kind.replace('_', ' ')} limit"
        if kind == "jerk":
            raise TimingFailed(
                f"the {timed.method} timing's accelerations jump between the samples at t = "
                f"{samples.t[sample]:.6g} s and {samples.t[sample + 1]:.6g} s: the jerk from the samples "
                f"exceeds the {what}"
            )
        raise TimingFailed(
            f"the {timed.method} timing's sample at t = {samples.t[sample]:.6g} s exceeds the {what} "
            "although its dense check holds; use more grid points"
        )
    utilization = _utilization(timed.stretches, margin)
    kappa_min, kappa_max, length, worst = conditioning_along(robot, samples.q)
    if not np.isfinite(kappa_max):
        notes.append(
            f"the arm passes through a singularity at t = {samples.t[worst]:.4g} s: its Jacobian loses rank "
            "there (the condition number is infinite)"
        )
    elif kappa_max > NEAR_SINGULAR_KAPPA:
        notes.append(
            f"the arm passes near a singularity: the Jacobian's condition number reaches {kappa_max:.4g} "
            f"at t = {samples.t[worst]:.4g} s"
        )
    switching = timed.switching_times
    if switching is None and timed.method == "collocation" and timing.torque_weight == 0.0:
        read = collocation_switches(samples.t, samples.tau, limits.torque, level=SATURATION_READ)
        switching = switching_times(read, robot.joint_names)
    s, sd, mvc = _phase_plane(timed.stretches)
    require_finite(timed.method, path_speed=sd, cost=timed.cost)
    return PlannedTrajectory(
        robot=robot.name,
        method=timed.method,
        joint_names=robot.joint_names,
        duration=result.duration,
        samples=samples,
        phase_plane=PhasePlane(s, sd, mvc, result.switch_points),
        peak_utilization=utilization,
        solve_ms=(time.perf_counter() - started) * 1e3,
        warnings=tuple(notes),
        binding=result.binding,
        conditioning=Conditioning(kappa_min, kappa_max, length),
        cost=timed.cost,
        solver=timed.solver,
        switching_times=switching,
        clearance=found_clearance,
        search=timed.search,
    )


def _round_up(value: float, digits: int = 3) -> float:
    """``value`` rounded up to ``digits`` significant digits."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.ceil(value / scale) * scale
