"""Joint trajectories through via points (lecture "Trajectory Planning": "the final velocities
and positions at the conclusion of each segment can be used as the initial values for the next
segments"): one cubic (continuous velocity) or quintic (continuous velocity and acceleration)
per joint and segment, each segment's duration the shortest that keeps every requested limit.

Via velocities follow the usual rule: the mean of the two adjacent segments' average slopes when
they agree in sign, else zero; quintic via accelerations the difference of those slopes over the
mean of the two durations. Durations and via states depend on each other, so a few rounds
alternate between them; the last round fixes the via states and shortens each segment alone,
so the final trajectory keeps every limit on every segment.

The result is a geometric path q(s) with s proportional to time, timed at constant path speed:
the rest of the planner (sampling, limits, phase plane) treats it like any other path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from toptraj.planners.errors import InfeasiblePath, InvalidRequest, NotServed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths.base import GeometricPath, PathPoints
from toptraj.planners.paths.waypoints import COINCIDENT
from toptraj.planners.timing.base import DenseStates, PathTiming
from toptraj.planners.timing.laws.profiles import cubic_coefficients, quintic_coefficients
from toptraj.robots import JointLimits, Robot

ROUNDS = 4
SAMPLES_PER_SEGMENT = 120


class ViaPath(GeometricPath):
    """q(s) = the segment polynomials at t = s T, for segment durations ``durations``.

    Args:
        coefficients: Shape (n_segments, n_dof, order + 1), polynomial in local time per joint.
        durations: Segment durations in s.
        total: Their sum T (s) as given (a duration asked for, of which the sum is a rounding);
            default the sum.
    """

    def __init__(self, coefficients: np.ndarray, durations: np.ndarray, total: float | None = None):
        self.coefficients = coefficients
        self.durations = np.asarray(durations, dtype=float)
        self.total = float(self.durations.sum()) if total is None else float(total)
        self.dof = coefficients.shape[1]
        self.starts = np.concatenate(([0.0], np.cumsum(self.durations)))
        self.knots = self.starts / self.total
        self.knots[-1] = 1.0
        self.kinks = np.empty(0)

    def _derivatives(self, s, side, orders):
        t = np.clip(np.asarray(s, dtype=float), 0.0, 1.0) * self.total
        segment = np.searchsorted(self.starts, t, side="left" if side == "left" else "right") - 1
        segment = np.clip(segment, 0, len(self.durations) - 1)
        local = t - self.starts[segment]
        out = []
        for order in orders:
            values = np.zeros((len(t), self.dof))
            for power in range(order, self.coefficients.shape[2]):
                factor = np.prod(np.arange(power - order + 1, power + 1)) if order else 1.0
                values += factor * self.coefficients[segment, :, power] * (local ** (power - order))[:, None]
            out.append(values * self.total**order)
        return out

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        return PathPoints(*self._derivatives(s, side, (0, 1, 2)))

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        return self._derivatives(s, side, (3,))[0]


@dataclass(frozen=True)
class ConstantSpeedTiming(PathTiming):
    """s = t / T: the timing of a ``ViaPath`` (its geometry already holds the time law)."""

    total: float
    knots: np.ndarray

    @property
    def duration(self) -> float:
        return self.total

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.total)
        return t / self.total, np.full_like(t, 1.0 / self.total), np.zeros_like(t)

    def dense_states(self, points_per_interval: int = 3) -> DenseStates:
        s = np.union1d(np.linspace(0.0, 1.0, 2001), self.knots)
        left = np.isin(s, self.knots[1:-1])
        s = np.concatenate([s, s[left]])
        flags = np.concatenate([np.zeros(len(s) - left.sum(), dtype=bool), np.ones(left.sum(), dtype=bool)])
        ones = np.full_like(s, 1.0 / self.total)
        return DenseStates(s, ones, np.zeros_like(s), np.zeros_like(s), flags)

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        return np.full_like(np.asarray(s, dtype=float), 1.0 / self.total)


def _segment(law, q0, v0, a0, q1, v1, a1, T):
    """Coefficients (n_dof, 6) of one segment, cubic padded with zeros."""
    rows = []
    for j in range(len(q0)):
        if law == "cubic":
            rows.append(np.concatenate([cubic_coefficients(q0[j], v0[j], q1[j], v1[j], T), [0.0, 0.0]]))
        else:
            rows.append(quintic_coefficients(q0[j], v0[j], a0[j], q1[j], v1[j], a1[j], T))
    return np.array(rows)


def _segment_ratio(robot, limits, kinds, coefficients, T) -> float:
    """Largest value / limit over samples of one segment."""
    t = np.linspace(0.0, T, SAMPLES_PER_SEGMENT + 1)
    powers = np.arange(coefficients.shape[1])
    q = (coefficients[None, :, :] * (t[:, None, None] ** powers)).sum(axis=2)
    d1 = (coefficients[None, :, 1:] * powers[1:] * (t[:, None, None] ** (powers[1:] - 1))).sum(axis=2)
    d2 = (coefficients[None, :, 2:] * (powers[2:] * (powers[2:] - 1)) * (t[:, None, None] ** (powers[2:] - 2))).sum(axis=2)
    d3 = (coefficients[None, :, 3:] * (powers[3:] * (powers[3:] - 1) * (powers[3:] - 2)) * (t[:, None, None] ** (powers[3:] - 3))).sum(axis=2)
    ratios = []
    with np.errstate(divide="ignore", invalid="ignore"):
        if "velocity" in kinds:
            ratios.append(np.abs(d1) / limits.velocity)
        if "acceleration" in kinds:
            ratios.append(np.abs(d2) / limits.acceleration)
        if "jerk" in kinds:
            ratios.append(np.abs(d3) / limits.jerk)
        if "torque" in kinds:
            ratios.append(np.abs(robot.inverse_dynamics(q, d1, d2)) / limits.torque)
    return float(max(np.nan_to_num(ratio, nan=0.0).max() for ratio in ratios))


def _shortest(robot, limits, kinds, law, states, guess, deadline: Deadline) -> float:
    """Shortest T for one segment between fixed boundary states (bisection on the ratio)."""
    q0, v0, a0, q1, v1, a1 = states

    def ratio(T):
        deadline.check()
        return _segment_ratio(robot, limits, kinds, _segment(law, q0, v0, a0, q1, v1, a1, T), T)

    high = guess
    for _ in range(60):
        if ratio(high) <= 1.0:
            break
        high *= 1.5
    else:
        raise InfeasiblePath("no segment duration meets the limits between these via points")
    low = high / 1.5
    while low > 1e-6 and ratio(low) <= 1.0:
        high, low = low, low / 1.5
    for _ in range(40):
        middle = 0.5 * (low + high)
        if ratio(middle) <= 1.0:
            high = middle
        else:
            low = middle
    return high


def _torque_time(robot: Robot, waypoints: np.ndarray, steps: np.ndarray, limits: JointLimits) -> np.ndarray:
    """A first duration (s) of each segment under torque limits, shape (n_segments,): a rest to
    rest cubic's peak acceleration 6 |step| / T^2 met with each joint's torque limit over its
    inertia M_jj at the segment's start (gravity and coupling left to the bisection that
    follows). Used where the velocity and acceleration guesses are zero (torque limits only):
    the via velocities of 1 ms segments were beyond any torque, and every segment was refused."""
    inertia = np.array([np.diag(pin.crba(robot.model, robot.data, robot.configuration(q))) for q in waypoints[:-1]])
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = np.nan_to_num(limits.torque / inertia, nan=np.inf)
        return np.sqrt(np.nan_to_num(6 * np.abs(steps) / reach, posinf=0.0).max(axis=1))


def via_point_trajectory(
    robot: Robot,
    waypoints: np.ndarray,
    law: str,
    limits: JointLimits,
    kinds: tuple[str, ...],
    duration: float | None,
    deadline: Deadline = NO_DEADLINE,
) -> tuple[ViaPath, ConstantSpeedTiming]:
    """The via-point trajectory through ``waypoints`` (n, n_dof) with ``law`` segments.

    Raises:
        BudgetExceeded: ``deadline`` passed (checked before every limit evaluation).
    """
    if law not in ("cubic", "quintic"):
        raise NotServed("method", law, law, rule="via_points_need_polynomials", alternatives=("cubic", "quintic"))
    steps = np.diff(waypoints, axis=0)
    if np.any(np.all(np.abs(steps) < COINCIDENT, axis=1)):
        index = int(np.flatnonzero(np.all(np.abs(steps) < COINCIDENT, axis=1))[0])
        raise InvalidRequest(f"waypoints[{index}]", waypoints[index], rule="waypoints_coincide", index=index, tolerance=COINCIDENT)
    n_segments, n_dof = steps.shape
    with np.errstate(divide="ignore"):
        velocity_time = np.nan_to_num(np.abs(steps) / limits.velocity, posinf=0.0).max(axis=1) * 1.5
        accel_time = np.sqrt(np.nan_to_num(6 * np.abs(steps) / limits.acceleration, posinf=0.0).max(axis=1))
    durations = np.maximum(velocity_time, accel_time)
    if "torque" in kinds and not durations.all():  # segments no joint limit bounds: the torques' guess
        durations = np.where(durations > 0.0, durations, _torque_time(robot, waypoints, steps, limits))
    durations = np.maximum(durations, 1e-3)
    for _ in range(ROUNDS + 1):
        slopes = steps / durations[:, None]
        velocities = np.zeros((n_segments + 1, n_dof))
        accelerations = np.zeros((n_segments + 1, n_dof))
        agree = np.sign(slopes[:-1]) == np.sign(slopes[1:])
        velocities[1:-1] = np.where(agree, 0.5 * (slopes[:-1] + slopes[1:]), 0.0)
        if law == "quintic":
            accelerations[1:-1] = (slopes[1:] - slopes[:-1]) / (0.5 * (durations[:-1] + durations[1:]))[:, None]
        durations = np.array([
            _shortest(
                robot, limits, kinds, law,
                (waypoints[k], velocities[k], accelerations[k], waypoints[k + 1], velocities[k + 1], accelerations[k + 1]),
                durations[k],
                deadline,
            )
            for k in range(n_segments)
        ])
    if duration is not None:
        # The shortest motion run k times as slowly: velocities scale by 1 / k, accelerations by
        # 1 / k^2, so that a duration above the shortest holds every joint limit it holds (its
        # own share of the duration per segment, not one shared otherwise).
        k = duration / durations.sum()
        durations, velocities, accelerations = durations * k, velocities / k, accelerations / k**2
    coefficients = np.array([
        _segment(law, waypoints[k], velocities[k], accelerations[k], waypoints[k + 1], velocities[k + 1], accelerations[k + 1], durations[k])
        for k in range(n_segments)
    ])
    path = ViaPath(coefficients, durations, duration)
    return path, ConstantSpeedTiming(path.total, path.knots)
