"""``plan``: from a robot and a motion request to a timed trajectory with torques.

Data flow (DESIGN.md): request -> GeometricPath q(s) -> PathConstraints on a grid (once) ->
timing method -> TimeScaling s(t) -> samples, phase plane and peak utilization.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from toptraj.planners.checks.gate import TimedStretch, gate_threshold, samples_exceed
from toptraj.planners.collision import Obstacle, check_clearance
from toptraj.planners.collision.obstacles import check_obstacles
from toptraj.planners.collision.self_collision import check_self_collision
from toptraj.planners.constraints.admissible import admissible_set
from toptraj.planners.constraints.tool_speed import tool_speed_limit
from toptraj.planners.errors import InvalidRequest, TimingFailed, numerical_breakdown_is_failure
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.collocation import FreeMotion
from toptraj.planners.generators.collocation.switching import collocation_switches, switching_times
from toptraj.planners.kinematics.conditioning import NEAR_SINGULAR_KAPPA, conditioning_along
from toptraj.planners.paths.blended import MIN_BLEND, BlendedPath
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.paths.grid import MAX_POINTS, spread_indices
from toptraj.planners.problem.ranges import DT, check_scaled_limits, check_timing
from toptraj.planners.problem.requests import Timing, WaypointPath, check_constraint_kinds, timing_method
from toptraj.planners.problem.waypoints import continuous_turns, make_path, without_repeats
from toptraj.planners.results import Accuracy, Conditioning, PhasePlane, PlannedTrajectory, require_finite
from toptraj.planners.runner.accuracy import answer_accuracy
from toptraj.planners.runner.given_path import timed_path, timed_unsynchronized, timed_via_points
from toptraj.planners.runner.timed_free import timed_free_motion, timed_search
from toptraj.planners.timing.base import TimingMethod
from toptraj.planners.timing.laws.law_timing import LawTiming
from toptraj.planners.timing.laws.method import ClassicalMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.planners.trajectory import sample_trajectory
from toptraj.robots import JointLimits, Robot

MAX_SAMPLES = 200_000
#: Seconds the sampling takes per sample and joint, with the checks, the conditioning and the
#: encoding of the answer that follow it (measured about 0.3 us on ur5 at 236 to 23,409
#: samples; twice that, for slower machines): what ``Deadline.expect`` is told before it.
SAMPLE_SECONDS = 5e-7
#: Largest number of phase-plane points returned (the grid is thinned evenly beyond it).
MAX_PHASE_PLANE_POINTS = 2_000
#: Largest number of samples whose Jacobian is conditioned (evenly spaced among them).
CONDITIONING_POINTS = 100
#: Share of its limit beyond which a sampled torque counts as saturated when switching times
#: are read off the samples.
SATURATION_READ = 0.98
#: Largest timing.limit_margin (a fraction of every limit kept in reserve).
MAX_LIMIT_MARGIN = 0.5


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
    keep = spread_indices(len(s), MAX_PHASE_PLANE_POINTS)
    return s[keep], sd[keep], mvc[keep]


def _utilization(stretches_, margin: float) -> dict[str, np.ndarray]:
    """Peak |value| / limit per kind and joint over every stretch, against the limits as
    requested (before any margin)."""
    kinds = stretches_[0].check.utilization.keys()
    if len(stretches_) == 1:
        return {kind: (1.0 - margin) * peak for kind, peak in stretches_[0].check.utilization.items()}
    return {
        kind: (1.0 - margin) * np.max([item.check.utilization[kind] for item in stretches_], axis=0)
        for kind in kinds
    }


def _unasked_limits(utilization: dict[str, np.ndarray], kinds: tuple[str, ...], method: TimingMethod, joint_names: tuple[str, ...]) -> list[str]:
    """A note for each joint limit the answer exceeds by more than ``UNASKED_EXCESS`` where
    that kind of limit was not among the constraints (``kinds``): the answer is right, but a
    reader of its peak utilization must not take it for a broken promise."""
    notes = []
    for kind, peak in utilization.items():
        peak = np.atleast_1d(np.asarray(peak, dtype=float))
        if kind in kinds or kind.startswith("tool") or not peak.size or not np.nanmax(peak) > UNASKED_EXCESS:
            continue
        joint = int(np.nanargmax(peak))
        name = joint_names[joint] if peak.size == len(joint_names) else f"joint {joint}"
        remedy = f"add {kind!r} to the constraints to hold it" if kind in method.kinds else f"{method.name} cannot hold {kind} limits"
        notes.append(f"the {kind} of joint {name!r} reaches {peak[joint]:.4g} times its limit, which was not asked for: {remedy}")
    return notes


#: Peak utilization of a limit kind not among the constraints above which the answer says so.
UNASKED_EXCESS = 1.005

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
    self_collision: bool = False,
) -> PlannedTrajectory:
    """Plan the timed trajectory of ``robot`` along ``path_spec``, sampled every ``dt`` seconds
    into at most ``max_samples`` samples. With ``exact_period`` the samples lie on whole periods
    ``dt``, the final state included: the motion is slowed uniformly to end on one
    (``toptraj.planners.trajectory.sample_trajectory``); ``duration`` stays the planned (optimal) one
    and ``sampled_duration`` is the samples' last instant. With ``obstacles`` (world frame),
    every link keeps ``clearance`` (m) from them along the path (``toptraj.planners.collision``), and
    the answer carries the smallest distance found. With ``self_collision`` no two links of the
    arm touch along the path (``toptraj.planners.collision.self_collision``; the search checks it
    always).

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
    check_obstacles(obstacles)
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
    check_scaled_limits(robot.limits.with_request(timing.limit_overrides), timing.limit_scales, robot.joint_names)
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
    self_checked = None
    if obstacles and isinstance(path_spec, FreeMotion) and method.name != "search":
        raise InvalidRequest(
            "path.obstacles on a free path are served by timing.method 'search' (the global search among obstacles); "
            "collocation does not see obstacles"
        )
    with numerical_breakdown_is_failure(method.name):
        if method.name == "search":
            timed = timed_search(robot, path_spec, timing, kinds, limits, timing_part, threshold, obstacles, clearance)
        elif isinstance(path_spec, FreeMotion) or method.name == "collocation":
            timed = timed_free_motion(robot, path_spec, method, timing, kinds, limits, timing_part, threshold)
        elif timing.synchronization == "none":
            timing_part.progress(0.0, "joint moves")
            timed = timed_unsynchronized(robot, path_spec, method, timing, kinds, limits, timing_part, threshold)
        elif isinstance(path_spec, WaypointPath) and path_spec.interpolation == "via":
            timing_part.progress(0.0, "via points")
            timed = timed_via_points(robot, path_spec, method, timing, kinds, limits, timing_part, threshold)
        else:
            timing_part.progress(0.0, "path")
            path = make_path(robot, path_spec, deadline)
            if obstacles:
                timing_part.progress(0.05, "clearance")
                checked_first = check_clearance(path, robot, list(obstacles), clearance, deadline)
            if self_collision:
                timing_part.progress(0.07, "self-collision")
                self_checked = check_self_collision(path, robot, deadline=deadline)
            timed = timed_path(robot, path, method, timing, kinds, limits, timing_part.within(0.1, 1.0), threshold)
    path, result, notes = timed.path, timed.timing, [*dropped, *timed.notes]
    if isinstance(path, BlendedPath) and path.tight_corners:
        notes.append(
            f"path.max_deviation = {path.max_deviation:g} is too small to blend the corners at waypoints "
            f"{', '.join(map(str, path.tight_corners))} (a blend shorter than {MIN_BLEND:g} of the path): the motion "
            "stops there"
        )
    deadline.check()
    found_clearance = None
    if obstacles:
        # a given path was checked before its timing; a path shaped with its timing (via points) now
        found_clearance = checked_first or check_clearance(path, robot, list(obstacles), clearance, deadline)
    if self_collision and self_checked is None and method.name != "search":  # the search checked its own path
        check_self_collision(path, robot, deadline=deadline)
    deadline.progress(0.9, "sampling")
    require_finite(timed.method, duration=result.duration)
    if result.duration / dt > max_samples - 2:
        raise InvalidRequest(_too_many_samples(result.duration, dt, max_samples, timing))
    deadline.expect((result.duration / dt + 2) * robot.dof * SAMPLE_SECONDS)
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
    timed_by = PhasePlaneMethod() if method.name == "search" else method  # the search's path: phase_plane
    # Time laws at their shortest, also through via points or joint by joint: every stretch
    # timed by a law, its peak utilization read off its dense check.
    by_law = isinstance(method, ClassicalMethod)
    laws = [
        (item.timing.duration, {kind: peak for kind, peak in item.check.utilization.items() if kind in kinds or kind.startswith("tool")})
        for item in timed.stretches
        if by_law or isinstance(item.timing, LawTiming)
    ]
    law = laws if len(laws) == len(timed.stretches) else None
    if timed.motion_gap is not None:  # a free path: the gap of the motion found, warned of where it is found
        accuracy, warning = Accuracy(*timed.motion_gap), None
    else:
        accuracy, warning = answer_accuracy(
            result, timed_by, timed.method, sum(len(item.constraints.s) - 1 for item in timed.stretches), robot.dof,
            grid_given=timing.grid_points is not None, duration_given=timing.duration is not None, law_utilization=law,
        )
    if warning is not None:
        notes.append(warning)
    utilization = _utilization(timed.stretches, margin)
    notes.extend(_unasked_limits(utilization, kinds, method, robot.joint_names))
    kappa_min, kappa_max, length, worst = conditioning_along(robot, samples.q, spread_indices(len(samples.q), CONDITIONING_POINTS))
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
        accuracy=accuracy,
    )


def _too_many_samples(duration: float, dt: float, max_samples: int, timing: Timing) -> str:
    """Why ``duration`` (s) sampled every ``dt`` (s) is not served, and advice that can be
    followed: the smallest ``output.dt`` that fits when it lies in ``DT``, else the limits that
    make the motion this slow (no ``output.dt`` beyond its own range is ever advised)."""
    given = f"output.dt = {dt:g} s gives {math.ceil(duration / dt) + 1} samples over the {duration:.4g} s motion; at most {max_samples} are served"
    needed = _round_up(duration / (max_samples - 2))
    if needed <= DT.high:
        return f"{given}: use output.dt >= {needed:g} s"
    slowing = [f"timing.limits.{name}" for name in ("tool_speed", "tool_angular_speed") if getattr(timing, name) is not None]
    slowing += ["the velocity and acceleration limits (timing.limits and their scales)"]
    return (
        f"{given}, and even the largest output.dt ({DT.high:g} s) serves at most {_round_down(DT.high * (max_samples - 2)):g} s "
        f"of motion: the limits make this motion too slow to serve; raise {' or '.join(slowing)}"
    )


def _round_down(value: float, digits: int = 3) -> float:
    """``value`` rounded down to ``digits`` significant digits."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.floor(value / scale) * scale


def _round_up(value: float, digits: int = 3) -> float:
    """``value`` rounded up to ``digits`` significant digits."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.ceil(value / scale) * scale
