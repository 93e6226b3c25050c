"""What a path built from a problem must satisfy before it is timed, and the grid and boundary
it is timed with: within the joint range, a finite jerk where jerk is limited, the boundary
velocities tangent to the path (as path speeds), a grid within the method's memory."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from toptraj.planners.errors import InfeasiblePath, NotServed, OutOfRange, OutsideJointRange
from toptraj.planners.paths import GeometricPath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.boundary import path_acceleration, path_speed
from toptraj.planners.problem.problem import BoundaryStates
from toptraj.planners.timing.base import Boundary, TimingMethod
from toptraj.robots import Robot


def check_within_joint_limits(robot: Robot, field: str, q: ArrayLike) -> None:
    """OutOfRange naming the joint, its value and its range where the configuration ``q``
    (n_dof,), given as ``field`` (a free path's start or goal), lies outside the joint limits."""
    q = np.asarray(q, dtype=float)
    outside = robot.outside_position_limits(q)
    if outside is not None:
        joint = outside[1]
        lower, upper = robot.limits.position_lower, robot.limits.position_upper
        raise OutOfRange(f"{field}[{joint}]", float(q[joint]), float(lower[joint]), float(upper[joint]),
                         rule="outside_joint_range", joint_name=robot.joint_names[joint], prismatic=robot.force_units[joint] == "N")


def check_path_within_limits(robot: Robot, path: GeometricPath, s: np.ndarray) -> None:
    """Splines may overshoot between waypoints: refuse a path that leaves the joint range (where
    it lies farthest outside on a spline; elsewhere, the first of 4 points per interval of the
    grid ``s`` that does)."""
    lower, upper = robot.limits.position_lower, robot.limits.position_upper
    outside = path.outside_range(lower, upper, 4 * len(s) + 1)
    if outside is not None:
        at, joint, value = outside
        raise OutsideJointRange(
            f"the interpolated path leaves the range [{lower[joint]:.6g}, {upper[joint]:.6g}] of joint "
            f"{robot.joint_names[joint]!r} at s = {at:.4f} (q = {value:.6g}); "
            "add waypoints or use interpolation 'linear'",
            s=at,
            joint=robot.joint_names[joint],
            value=float(value),
            lower=float(lower[joint]),
            upper=float(upper[joint]),
        )


def check_jerk_finite(path: GeometricPath, kinds: tuple[str, ...], method: str = "") -> None:
    """A jerk limit needs a path whose d2q/ds2 is continuous where the motion goes on: at a
    break (a straight segment meeting a circular blend) the joint acceleration q'' sd^2 jumps
    unless the motion stops there, an infinite jerk. ``method``: the timing method's name, a
    fact of the refusal (a method that always limits jerk is no remedy)."""
    if "jerk" not in kinds or not len(path.breaks):
        return
    s = float(path.breaks[0])
    raise InfeasiblePath(
        f"the path's curvature d2q/ds2 jumps at s = {s:.4f} (where a straight segment meets a blend): "
        "no motion that passes it has a finite jerk",
        s=s,
        limit="jerk",
        rule="curvature_jump",
        method=method,
    )


def moving_velocity(velocity: ArrayLike | None) -> ArrayLike | None:
    """A boundary velocity, or ``None`` for rest (a zero vector included)."""
    if velocity is None or not np.any(np.asarray(velocity) != 0.0):
        return None
    return velocity


def path_boundary(path: GeometricPath, states: BoundaryStates, duration: float | None, method: TimingMethod) -> Boundary:
    """The joint boundary ``states`` as path speeds and accelerations along ``path``, for
    ``method`` (which must take the accelerations and the ``duration`` given)."""
    if (states.start_acceleration is not None or states.end_acceleration is not None) and not method.takes_acceleration_boundary:
        raise NotServed("boundary", None, method.name, rule="boundary_accelerations_not_used", alternatives=("quintic",))
    if duration is not None and not method.takes_duration:
        raise NotServed("duration", duration, method.name, rule="duration_not_used")
    sd_start = path_speed(path, states.start_velocity, 0.0, "boundary.start_velocity")
    sd_end = path_speed(path, states.end_velocity, 1.0, "boundary.end_velocity")
    return Boundary(
        sd_start=sd_start,
        sd_end=sd_end,
        sdd_start=path_acceleration(path, states.start_acceleration, sd_start, 0.0, "boundary.start_acceleration"),
        sdd_end=path_acceleration(path, states.end_acceleration, sd_end, 1.0, "boundary.end_acceleration"),
    )


def timing_grid(path: GeometricPath, n_intervals: int | None, method: TimingMethod, robot: Robot, s: np.ndarray | None = None) -> np.ndarray:
    """The grid of ``path`` (``n_intervals``, else the default; ``s``: that grid, already
    built), within what ``method`` serves on ``robot``: a long path's default grid is thinned to
    ``method.max_grid_intervals``."""
    s = path_grid(path, n_intervals) if s is None else s
    cap = method.max_grid_intervals(robot.dof)
    return s if len(s) - 1 <= cap else path_grid(path, cap)
