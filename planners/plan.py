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

from planners.constraints import build_path_constraints
from planners.deadline import NO_DEADLINE, Deadline
from planners.errors import InfeasiblePath, InvalidRequest
from planners.grid import MAX_POINTS, path_grid
from planners.kinematics.conditioning import NEAR_SINGULAR_KAPPA, conditioning_along
from planners.mvc import admissible_set
from planners.paths import GeometricPath, SplinePath, StopAndGoPath
from planners.free_path import FreeMotion, collocation_path, optimize_motion
from planners.paths.cartesian import CartesianLine, cartesian_path
from planners.boundary import path_acceleration, path_speed
from planners.requests import Timing, WaypointPath, check_constraint_kinds, timing_method
from planners.results import Conditioning, PhasePlane, PlannedTrajectory
from planners.constraints import PathConstraints
from planners.timing.base import Boundary, PathTiming, TimingMethod
from planners.timing.min_cost import MinCostMethod
from planners.timing.phase_plane import PhasePlaneMethod
from planners.trajectory import peak_utilization, sample_trajectory
from planners.via_points import via_point_trajectory
from robots import JointLimits, Robot

INTERPOLATIONS = {"spline": SplinePath, "linear": StopAndGoPath}
MAX_WAYPOINTS = 1_000
#: Largest joint coordinate accepted (rad or m): a continuous joint may turn many times, not 1e300.
MAX_COORDINATE = 1e4
MAX_SAMPLES = 200_000
#: Largest number of phase-plane points returned (the grid is thinned evenly beyond it).
MAX_PHASE_PLANE_POINTS = 2_000


def checked_waypoints(robot: Robot, spec: WaypointPath) -> np.ndarray:
    """The waypoints of ``spec`` as an (n, n_dof) array, checked against the robot."""
    if spec.interpolation not in (*INTERPOLATIONS, "via"):
        raise InvalidRequest(
            f"path.interpolation {spec.interpolation!r} is unknown; use one of {sorted([*INTERPOLATIONS, 'via'])}"
        )
    waypoints = np.asarray(spec.waypoints, dtype=float) if np.ndim(spec.waypoints) == 2 else None
    if waypoints is None:
        raise InvalidRequest("path.waypoints must be a list of joint vectors (a 2-D array)")
    count, width = waypoints.shape
    if count < 2:
        raise InvalidRequest(f"path.waypoints holds {count} waypoint(s); at least 2 are needed")
    if count > MAX_WAYPOINTS:
        raise InvalidRequest(f"path.waypoints holds {count} waypoints; at most {MAX_WAYPOINTS} are served")
    if width != robot.dof:
        raise InvalidRequest(
            f"path.waypoints[0] has {width} values; {robot.name} has {robot.dof} joints "
            f"({', '.join(robot.joint_names)})"
        )
    bad = np.argwhere(~np.isfinite(waypoints) | (np.abs(waypoints) > MAX_COORDINATE))
    if bad.size:
        raise InvalidRequest(
            f"path.waypoints[{bad[0][0]}][{bad[0][1]}] is {waypoints[tuple(bad[0])]:.6g}: not a finite "
            f"number within +-{MAX_COORDINATE:g} (rad or m)"
        )
    lower, upper = robot.limits.position_lower, robot.limits.position_upper
    outside = robot.outside_position_limits(waypoints)
    if outside is not None:
        index, joint = outside
        raise InvalidRequest(
            f"path.waypoints[{index}][{joint}] = {waypoints[index, joint]:.6g} is outside the limits "
            f"[{lower[joint]:.6g}, {upper[joint]:.6g}] of joint {robot.joint_names[joint]!r}"
        )
    return waypoints


def make_path(robot: Robot, spec: "WaypointPath | CartesianLine", deadline: Deadline = NO_DEADLINE) -> GeometricPath:
    """The geometric path of a Cartesian line, or of joint waypoints interpolated by spline or
    linear segments (via points are timed and shaped together, in ``via_points``)."""
    if isinstance(spec, CartesianLine):
        return cartesian_path(robot, spec, deadline)
    return INTERPOLATIONS[spec.interpolation](checked_waypoints(robot, spec))


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


def _moving(velocity):
    """A boundary velocity, or ``None`` for rest (a zero vector included)."""
    if velocity is None or not np.any(np.asarray(velocity) != 0.0):
        return None
    return velocity


def _free_motion(robot, path_spec, method, timing: Timing, limits, deadline):
    """Path and timing optimized together (``path.kind = "free"`` with ``collocation``)."""
    if not isinstance(path_spec, FreeMotion) or method.name != "collocation":
        raise InvalidRequest("a free path (start and goal only) needs timing.method 'collocation', and collocation a free path")
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
    return path, solver, timed


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
    """A path with its timing, the constraints it was timed under, and what to tell about it."""

    path: GeometricPath
    timing: PathTiming
    constraints: PathConstraints
    method: str
    notes: tuple[str, ...] = ()
    cost: float | None = None
    solver: dict | None = None


def _grid(path: GeometricPath, n_intervals: int | None, method: TimingMethod, robot: Robot) -> np.ndarray:
    """The grid of ``path`` (``n_intervals``, else the default), within what ``method`` serves on
    ``robot``: a long path's default grid is thinned to ``method.max_grid_intervals``."""
    s = path_grid(path, n_intervals)
    cap = method.max_grid_intervals(robot.dof)
    return s if len(s) - 1 <= cap else path_grid(path, cap)


def _timed_path(robot, path, method, timing, kinds, limits, deadline) -> _Timed:
    """A given path timed by ``method``."""
    s = _grid(path, timing.grid_points, method, robot)
    _check_path_within_limits(robot, path, s)
    boundary = _boundary(path, timing, method)
    constraints = build_path_constraints(path, robot, limits, kinds, s, deadline)
    deadline.check()
    result = method.solve(constraints, boundary, timing.duration, deadline)
    return _Timed(path, result, constraints, method.name, cost=getattr(result, "cost", None))


def _timed_via_points(robot, spec, method, timing, kinds, limits, deadline) -> _Timed:
    """Via points: segments shaped and timed together by the limits."""
    if timing.start_velocity is not None or timing.end_velocity is not None:
        raise InvalidRequest("via-point trajectories start and end at rest: leave timing.boundary out")
    path, result = via_point_trajectory(robot, checked_waypoints(robot, spec), method.name, limits, kinds, timing.duration, deadline)
    s = _grid(path, timing.grid_points, method, robot)
    _check_path_within_limits(robot, path, s)
    constraints = build_path_constraints(path, robot, limits, tuple(k for k in kinds if k != "jerk"), s, deadline)
    return _Timed(path, result, constraints, method.name)


def _timed_free_motion(robot, spec, method, timing, kinds, limits, deadline) -> _Timed:
    """A free motion: the collocation's path, re-timed exactly along itself (phase_plane, or
    min_cost for beta > 0) so that every limit holds between the collocation instants too."""
    path, solver, collocation_timing = _free_motion(robot, spec, method, timing, limits, deadline)
    retimer = PhasePlaneMethod() if timing.torque_weight == 0.0 else MinCostMethod(timing.torque_weight)
    constraints = build_path_constraints(path, robot, limits, kinds, _grid(path, None, retimer, robot), deadline)
    moving = dataclasses.replace(
        timing, start_velocity=_moving(spec.start_velocity), end_velocity=_moving(spec.end_velocity), duration=None
    )
    notes = ()
    try:
        result = retimer.solve(constraints, _boundary(path, moving, retimer), None, deadline)
    except InfeasiblePath as error:
        # A boundary state right at a limit may be out of reach of the conservative re-timing;
        # the collocation's own timing is then returned as it is.
        result = collocation_timing
        notes = (f"the collocation's own timing is returned (re-timing along its path failed: {error.detail})",)
    cost = getattr(result, "cost", None) if timing.torque_weight else result.duration
    return _Timed(path, result, constraints, "collocation", notes, cost, solver)


def plan(
    robot: Robot,
    path_spec: "WaypointPath | CartesianLine",
    timing: Timing = Timing(),
    dt: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
    max_samples: int = MAX_SAMPLES,
) -> PlannedTrajectory:
    """Plan the timed trajectory of ``robot`` along ``path_spec``, sampled every ``dt`` seconds
    into at most ``max_samples`` samples.

    Raises:
        InvalidRequest: malformed input (the message names the field), or a ``dt`` that gives
            more than ``max_samples`` samples (the message names the smallest that fits).
        InfeasiblePath: no timing can follow the path within the limits (says where).
        TimingFailed: the timing method failed.
        BudgetExceeded: ``deadline`` passed.
    """
    started = time.perf_counter()
    method = timing_method(timing)
    kinds = check_constraint_kinds(timing.constraints, method)
    if not (np.isfinite(dt) and dt > 0.0):
        raise InvalidRequest(f"output.dt must be a positive number of seconds, got {dt}")
    if timing.grid_points is not None and not 2 <= timing.grid_points <= MAX_POINTS:
        raise InvalidRequest(f"timing.grid_points must lie in [2, {MAX_POINTS}], got {timing.grid_points}")
    if timing.grid_points is not None and timing.grid_points > method.max_grid_intervals(robot.dof):
        raise InvalidRequest(
            f"timing.grid_points = {timing.grid_points} is more than {method.name} serves on a "
            f"{robot.dof}-joint robot (its memory grows with grid intervals times joints): use "
            f"timing.grid_points <= {method.max_grid_intervals(robot.dof)}"
        )
    if timing.duration is not None and not (np.isfinite(timing.duration) and timing.duration > 0):
        raise InvalidRequest(f"timing.duration must be a positive number of seconds, got {timing.duration}")
    limits: JointLimits = robot.limits.with_request(timing.limit_overrides, timing.limit_scales)
    if method.two_waypoints_only and (not isinstance(path_spec, WaypointPath) or len(path_spec.waypoints) != 2):
        given = f"{len(path_spec.waypoints)} waypoints" if isinstance(path_spec, WaypointPath) else "a cartesian path"
        raise InvalidRequest(
            f"timing.method {method.name!r} plans state-to-state motions: give exactly 2 waypoints, not "
            f"{given} (the offline library has no intermediate waypoints); use phase_plane or a time "
            "law through several waypoints"
        )
    if isinstance(path_spec, FreeMotion) or method.name == "collocation":
        timed = _timed_free_motion(robot, path_spec, method, timing, kinds, limits, deadline)
    elif isinstance(path_spec, WaypointPath) and path_spec.interpolation == "via":
        timed = _timed_via_points(robot, path_spec, method, timing, kinds, limits, deadline)
    else:
        timed = _timed_path(robot, make_path(robot, path_spec, deadline), method, timing, kinds, limits, deadline)
    path, result, constraints, notes = timed.path, timed.timing, timed.constraints, list(timed.notes)
    s = constraints.s
    deadline.check()
    if result.duration / dt > max_samples - 2:
        raise InvalidRequest(
            f"output.dt = {dt:g} s gives {math.ceil(result.duration / dt) + 1} samples over the "
            f"{result.duration:.4g} s motion; at most {max_samples} are served: use output.dt >= "
            f"{_round_up(result.duration / (max_samples - 2)):g} s"
        )
    samples = sample_trajectory(path, result, robot, dt)
    utilization = peak_utilization(path, result, robot, limits)
    kappa_min, kappa_max, length, worst = conditioning_along(robot, samples.q)
    notes += _warnings(utilization, kinds, robot)
    if kappa_max > NEAR_SINGULAR_KAPPA:
        notes.append(
            f"the arm passes near a singularity: the Jacobian's condition number reaches {kappa_max:.4g} "
            f"at t = {samples.t[worst]:.4g} s"
        )
    sd = result.speed_at(s)
    mvc = admissible_set(constraints.linearized(sd**2), constraints.sd_max**2).sd_max
    keep = np.unique(np.linspace(0, len(s) - 1, min(len(s), MAX_PHASE_PLANE_POINTS)).round().astype(int))
    return PlannedTrajectory(
        robot=robot.name,
        method=timed.method,
        joint_names=robot.joint_names,
        duration=result.duration,
        samples=samples,
        phase_plane=PhasePlane(s[keep], sd[keep], mvc[keep], result.switch_points),
        peak_utilization=utilization,
        solve_ms=(time.perf_counter() - started) * 1e3,
        warnings=tuple(notes),
        binding=result.binding,
        conditioning=Conditioning(kappa_min, kappa_max, length),
        cost=timed.cost,
        solver=timed.solver,
    )


def _round_up(value: float, digits: int = 3) -> float:
    """``value`` rounded up to ``digits`` significant digits."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.ceil(value / scale) * scale


def _warnings(utilization: dict[str, np.ndarray], kinds: tuple[str, ...], robot: Robot) -> list[str]:
    notes = []
    for kind in kinds:
        if kind not in utilization:
            continue
        worst = int(np.argmax(utilization[kind]))
        if utilization[kind][worst] > 1.005:
            notes.append(
                f"{kind} limit of joint {robot.joint_names[worst]!r} exceeded by "
                f"{100 * (utilization[kind][worst] - 1):.2f} %"
            )
    return notes
