"""``plan``: from a robot and a motion request to a timed trajectory with torques.

Data flow (DESIGN.md): request -> GeometricPath q(s) -> PathConstraints on a grid (once) ->
timing method -> TimeScaling s(t) -> samples, phase plane and peak utilization.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from planners.constraints import CONSTRAINT_KINDS, build_path_constraints
from planners.deadline import NO_DEADLINE, Deadline
from planners.errors import InfeasiblePath, InvalidRequest
from planners.grid import MAX_POINTS, path_grid
from planners.kinematics.conditioning import NEAR_SINGULAR_KAPPA, conditioning_along
from planners.mvc import admissible_set
from planners.paths import GeometricPath, SplinePath, StopAndGoPath
from planners.free_path import FreeMotion, collocation_path, optimize_motion
from planners.paths.cartesian import CartesianLine, cartesian_path
from planners.boundary import path_acceleration, path_speed
from planners.timing import METHODS
from planners.timing.base import Binding, Boundary, TimingMethod
from planners.timing.classical import ClassicalMethod
from planners.timing.min_cost import MinCostMethod
from planners.timing.collocation_method import CollocationMethod
from planners.timing.phase_plane import PhasePlaneMethod
from planners.timing.laws import TrapezoidalProfile
from planners.via_points import via_point_trajectory
from planners.trajectory import Samples, peak_utilization, sample_trajectory
from robots import JointLimits, Robot

INTERPOLATIONS = {"spline": SplinePath, "linear": StopAndGoPath}
MAX_WAYPOINTS = 1_000
#: Largest joint coordinate accepted (rad or m): a continuous joint may turn many times, not 1e300.
MAX_COORDINATE = 1e4
MAX_SAMPLES = 200_000
#: Largest number of phase-plane points returned (the grid is thinned evenly beyond it).
MAX_PHASE_PLANE_POINTS = 2_000


@dataclass(frozen=True)
class WaypointPath:
    """A joint path through ``waypoints`` (shape (n_waypoints, n_dof), joint units), interpolated
    by ``"spline"`` (C2 cubic), ``"linear"`` (straight segments, stopping at each waypoint), or
    ``"via"`` (per-joint cubic or quintic segments in time through the via points, the law named
    by the timing method)."""

    waypoints: np.ndarray
    interpolation: str = "spline"


@dataclass(frozen=True)
class Timing:
    """How to time the path.

    Attributes:
        method: A ``timing.method`` name (see ``planners.timing.METHODS``).
        constraints: Which limits to respect, among velocity, acceleration and torque.
        limit_overrides: Per-joint replacements, keys ``velocity``, ``acceleration``, ``jerk``,
            ``torque``.
        limit_scales: Factors on those limits, same keys.
        grid_points: Number of grid intervals; ``None`` chooses one from the path.
        start_velocity, end_velocity: Joint velocities at the ends (rad/s), tangent to the path;
            ``None`` is rest.
        start_acceleration, end_acceleration: Joint accelerations at the ends (rad/s^2), for the
            laws that take them (quintic).
        duration: Seconds, for the time laws; ``None`` asks for the shortest within the limits.
        trapezoid_fractions: (tau1, tau2), the trapezoidal law's ends of acceleration and of
            cruise as fractions of the duration.
        torque_weight: beta of the cost integral of (1 + beta |tau|^2) dt, in 1/(N m)^2, for
            ``min_cost``.
    """

    method: str = "phase_plane"
    constraints: tuple[str, ...] = ("velocity", "acceleration", "torque")
    limit_overrides: dict[str, list[float] | None] = field(default_factory=dict)
    limit_scales: dict[str, float | None] = field(default_factory=dict)
    grid_points: int | None = None
    start_velocity: np.ndarray | None = None
    end_velocity: np.ndarray | None = None
    start_acceleration: np.ndarray | None = None
    end_acceleration: np.ndarray | None = None
    duration: float | None = None
    trapezoid_fractions: tuple[float, float] = (1.0 / 3.0, 2.0 / 3.0)
    torque_weight: float = 0.0


@dataclass(frozen=True)
class PhasePlane:
    """The (s, sd) picture: the timing's path speed and the maximum velocity curve, in 1/s."""

    s: np.ndarray
    sd: np.ndarray
    sd_max: np.ndarray
    switch_points: tuple[tuple[float, str], ...]


@dataclass(frozen=True)
class Conditioning:
    """Frobenius condition number of the end effector's Jacobian along the trajectory
    (``planners.kinematics.conditioning``), with the characteristic length L in m."""

    kappa_min: float
    kappa_max: float
    characteristic_length: float


@dataclass(frozen=True)
class PlannedTrajectory:
    """What ``plan`` returns: samples and diagnostics of one timed path."""

    robot: str
    method: str
    joint_names: tuple[str, ...]
    duration: float
    samples: Samples
    phase_plane: PhasePlane
    peak_utilization: dict[str, np.ndarray]
    solve_ms: float
    warnings: tuple[str, ...]
    binding: Binding | None = None
    conditioning: Conditioning | None = None
    cost: float | None = None
    solver: dict | None = None


def make_path(robot: Robot, spec: "WaypointPath | CartesianLine") -> GeometricPath | None:
    """The geometric path of ``spec``, after checking it against the robot (``None`` for via
    points, whose geometry depends on their timing)."""
    if isinstance(spec, CartesianLine):
        return cartesian_path(robot, spec)
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
    if spec.interpolation == "via":
        return None
    return INTERPOLATIONS[spec.interpolation](waypoints)


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


def _check_constraint_kinds(kinds, method: TimingMethod) -> tuple[str, ...]:
    unknown = [kind for kind in kinds if kind not in CONSTRAINT_KINDS]
    if unknown:
        raise InvalidRequest(f"timing.constraints holds {unknown[0]!r}; use any of {list(CONSTRAINT_KINDS)}")
    unsupported = [kind for kind in kinds if kind not in method.kinds]
    if unsupported:
        hint = " (for jerk, use a time law or ruckig)" if unsupported[0] == "jerk" else ""
        raise InvalidRequest(
            f"timing.method {method.name!r} cannot limit {unsupported[0]}; it handles "
            f"{sorted(method.kinds)}{hint}"
        )
    kinds = tuple(dict.fromkeys([*kinds, *sorted(method.required_kinds)]))
    if not kinds:
        raise InvalidRequest("timing.constraints is empty: without limits the time-optimal motion is instantaneous")
    return kinds


def timing_method(timing: Timing) -> TimingMethod:
    """The method named by ``timing.method`` (with its per-request options)."""
    if timing.method == "trapezoidal":
        tau1, tau2 = timing.trapezoid_fractions
        if not (np.isfinite(tau1) and np.isfinite(tau2) and 0.0 < tau1 <= tau2 < 1.0):
            raise InvalidRequest(f"timing.trapezoid needs 0 < tau1 <= tau2 < 1, got {tau1}, {tau2}")
        return ClassicalMethod(TrapezoidalProfile(tau1, tau2))
    if timing.torque_weight != 0.0 and timing.method not in ("min_cost", "collocation"):
        raise InvalidRequest(f"timing.cost.torque_weight is not used by timing.method {timing.method!r}; use min_cost")
    if timing.method == "min_cost":
        if not (np.isfinite(timing.torque_weight) and timing.torque_weight >= 0.0):
            raise InvalidRequest(f"timing.cost.torque_weight must be a non-negative number, got {timing.torque_weight}")
        return MinCostMethod(timing.torque_weight)
    if timing.method == "collocation":
        return CollocationMethod()
    method = METHODS.get(timing.method)
    if method is None:
        raise InvalidRequest(f"timing.method {timing.method!r} is unknown; use one of {sorted(METHODS)}")
    return method


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


def plan(
    robot: Robot,
    path_spec: "WaypointPath | CartesianLine",
    timing: Timing = Timing(),
    dt: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
) -> PlannedTrajectory:
    """Plan the timed trajectory of ``robot`` along ``path_spec``.

    Raises:
        InvalidRequest: malformed input (the message names the field).
        InfeasiblePath: no timing can follow the path within the limits (says where).
        TimingFailed: the timing method failed.
        BudgetExceeded: ``deadline`` passed.
    """
    started = time.perf_counter()
    method = timing_method(timing)
    kinds = _check_constraint_kinds(timing.constraints, method)
    if not (np.isfinite(dt) and dt > 0.0):
        raise InvalidRequest(f"output.dt must be a positive number of seconds, got {dt}")
    if timing.grid_points is not None and not 2 <= timing.grid_points <= MAX_POINTS:
        raise InvalidRequest(f"timing.grid_points must lie in [2, {MAX_POINTS}], got {timing.grid_points}")
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
    solver, notes = None, []
    if isinstance(path_spec, FreeMotion) or method.name == "collocation":
        # The optimized path, re-timed exactly along itself: every limit then holds between the
        # collocation instants too, and the duration checks the collocation's own.
        path, solver, collocation_timing = _free_motion(robot, path_spec, method, timing, limits, deadline)
        method = PhasePlaneMethod() if timing.torque_weight == 0.0 else MinCostMethod(timing.torque_weight)
        s = path_grid(path, None)
        constraints = build_path_constraints(path, robot, limits, kinds, s, deadline)
        moving = dataclasses.replace(
            timing,
            start_velocity=_moving(path_spec.start_velocity),
            end_velocity=_moving(path_spec.end_velocity),
            duration=None,
        )
        try:
            result = method.solve(constraints, _boundary(path, moving, method), None, deadline)
        except InfeasiblePath as error:
            # A boundary state right at a limit may be out of reach of the conservative re-timing;
            # the collocation's own timing is then returned as it is.
            result = collocation_timing
            notes.append(f"the collocation's own timing is returned (re-timing along its path failed: {error.detail})")
        method = CollocationMethod()
    elif (path := make_path(robot, path_spec)) is None:
        if timing.start_velocity is not None or timing.end_velocity is not None:
            raise InvalidRequest("via-point trajectories start and end at rest: leave timing.boundary out")
        path, result = via_point_trajectory(
            robot, np.asarray(path_spec.waypoints, dtype=float), method.name, limits, kinds, timing.duration
        )
        s = path_grid(path, timing.grid_points)
        _check_path_within_limits(robot, path, s)
        constraints = build_path_constraints(path, robot, limits, tuple(k for k in kinds if k != "jerk"), s, deadline)
    else:
        s = path_grid(path, timing.grid_points)
        _check_path_within_limits(robot, path, s)
        boundary = _boundary(path, timing, method)
        constraints = build_path_constraints(path, robot, limits, kinds, s, deadline)
        deadline.check()
        result = method.solve(constraints, boundary, timing.duration, deadline)
    deadline.check()
    if result.duration / dt > MAX_SAMPLES:
        raise InvalidRequest(
            f"output.dt = {dt} s gives more than {MAX_SAMPLES} samples over {result.duration:.4g} s"
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
        method=method.name,
        joint_names=robot.joint_names,
        duration=result.duration,
        samples=samples,
        phase_plane=PhasePlane(s[keep], sd[keep], mvc[keep], result.switch_points),
        peak_utilization=utilization,
        solve_ms=(time.perf_counter() - started) * 1e3,
        warnings=tuple(notes),
        binding=result.binding,
        conditioning=Conditioning(kappa_min, kappa_max, length),
        cost=getattr(result, "cost", None) if solver is None or timing.torque_weight else result.duration,
        solver=solver,
    )


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
