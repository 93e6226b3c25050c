"""What a caller asks of ``plan``: the path (joint waypoints; Cartesian lines and free motions
live with their planners) and the timing, and the timing method that a request names."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from planners.constraints import CONSTRAINT_KINDS
from planners.errors import InvalidRequest
from planners.timing import METHODS
from planners.timing.base import TimingMethod
from planners.timing.classical import ClassicalMethod
from planners.timing.collocation_method import CollocationMethod
from planners.timing.laws import TrapezoidalProfile
from planners.timing.min_cost import MinCostMethod

#: Largest distance of a blend from its waypoint when a request names none (joint units): the
#: default path tolerance of MoveIt's time-optimal trajectory generation.
DEFAULT_MAX_DEVIATION = 0.1


@dataclass(frozen=True)
class WaypointPath:
    """A joint path through ``waypoints`` (shape (n_waypoints, n_dof), joint units), interpolated
    by ``"spline"`` (C2 cubic), ``"linear"`` (straight segments, stopping at each waypoint),
    ``"blend"`` (straight segments joined by circular blends within ``max_deviation`` of each
    waypoint, joint-space norm in joint units; default ``DEFAULT_MAX_DEVIATION``) or ``"via"``
    (per-joint cubic or quintic segments in time through the via points, the law named by the
    timing method). Continuous joints (no position limits) follow the numbers given
    (``continuous = "as_given"``) or turn the short way between waypoints (``"shortest"``)."""

    waypoints: np.ndarray
    interpolation: str = "spline"
    max_deviation: float | None = None
    continuous: str = "as_given"


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
        limit_margin: Fraction of every velocity, acceleration, jerk, torque and tool-speed
            limit kept in reserve (0 to 0.5): the timing is planned under the limits times
            (1 - margin), and with a positive margin no returned state exceeds the limits
            themselves.
        tool_speed: Largest linear speed of the tool frame's origin, m/s; ``None``: none.
        tool_angular_speed: Largest angular speed of the tool frame, rad/s; ``None``: none.
        tool_frame: The frame those speeds limit; ``None``: the robot's end effector.
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
    limit_margin: float = 0.0
    tool_speed: float | None = None
    tool_angular_speed: float | None = None
    tool_frame: str | None = None


def check_constraint_kinds(kinds, method: TimingMethod) -> tuple[str, ...]:
    unknown = [kind for kind in kinds if kind not in CONSTRAINT_KINDS]
    if unknown:
        raise InvalidRequest(f"timing.constraints holds {unknown[0]!r}; use any of {list(CONSTRAINT_KINDS)}")
    unsupported = [kind for kind in kinds if kind not in method.kinds]
    if unsupported:
        hint = " (for jerk, use jerk_limited, a time law or ruckig)" if unsupported[0] == "jerk" else ""
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
