"""Non-normalized joint moves (lecture "Trajectory Planning", "Basics of Trajectory Planning"):
every joint runs the time law on its own, at its own full speed, from its start to its goal.

The lecture's 2-DOF arm goes from A (alpha = 20 deg, beta = 30 deg) to B (40 deg, 80 deg) with
both joints limited to 10 deg/s. Non-normalized, alpha is done after 2 s and beta after 5 s: the
joint path is no longer the straight line from A to B but bends where alpha stops ("the path is
irregular"). Normalized (the straight joint line timed as one, ``timing.synchronization =
"normalized"``, what the other laws do), alpha moves at 4 deg/s, beta at 10 deg/s, and both stop
at 5 s.

Joint j moves by D_j with the normalized law sigma in its own shortest duration

    T_j = max(|D_j| max|sigma'| / v_j, sqrt(|D_j| max|sigma''| / a_j), cbrt(|D_j| max|sigma'''| / j_j))

over the velocity, acceleration and jerk limits asked for. Torque couples the joints: when it is
asked for, every T_j is stretched by one common factor k >= 1 (bisection), the smallest for which
the torques hold; a given duration sets k = duration / max T_j. As with via points, the motion is
returned as a geometric path q(s) with s proportional to time (``JointLawPath``), timed at
constant path speed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.errors import Conflicting, InfeasiblePath, LimitExceeded
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.via_points import ConstantSpeedTiming
from toptraj.planners.paths.base import GeometricPath, PathPoints
from toptraj.planners.timing.base import Binding
from toptraj.planners.timing.laws.profiles import NormalizedProfile
from toptraj.robots import JointLimits, Robot

#: Samples of tau for the law's peak derivatives (its knots are added).
PEAK_SAMPLES = 4001
#: Samples of s for the torque check while searching the common factor.
TORQUE_SAMPLES = 801
#: The order of the derivative of q each limit kind bounds (``_peaks`` lists them from 1).
ORDERS = {"velocity": 1, "acceleration": 2, "jerk": 3}
#: Share by which a given duration may fall short of the slowest joint's own before it is
#: refused (rounding of a duration the answer printed).
SHORTER = 1e-9


class JointLawPath(GeometricPath):
    """q_j(s) = start_j + D_j sigma(min(s T / T_j, 1)), T = max T_j: each joint follows the law
    in its own duration T_j and then rests.

    Args:
        start, goal: Joint positions, shape (n_dof,).
        profile: The normalized law sigma.
        durations: T_j in s, shape (n_dof,); 0 for a joint that does not move.
    """

    def __init__(self, start: np.ndarray, goal: np.ndarray, profile: NormalizedProfile, durations: np.ndarray):
        self.q_start = np.asarray(start, dtype=float)
        self.span = np.asarray(goal, dtype=float) - self.q_start
        self.profile = profile
        self.durations = np.asarray(durations, dtype=float)
        self.total = float(self.durations.max())
        self.dof = len(self.q_start)
        moving = self.durations > 0
        # d(tau_j)/ds for each joint: tau_j = s T / T_j.
        self.rate = np.where(moving, self.total / np.where(moving, self.durations, 1.0), 0.0)
        ends = [profile.knots() * T / self.total for T in self.durations[moving]]
        self.knots = np.union1d(np.concatenate([[0.0, 1.0], *ends]), [])
        self.kinks = np.empty(0)
        self.breaks = self.knots[1:-1]

    def _joint(self, s, side):
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        tau = s[:, None] * self.rate[None, :]
        done = (tau > 1.0) | ((tau >= 1.0) & (side == "right")) | (self.rate[None, :] == 0.0)
        sigma, d1, d2, d3 = (np.asarray(v).reshape(tau.shape) for v in self.profile.derivatives(np.minimum(tau, 1.0).ravel()))
        running = ~done
        return (
            self.q_start + self.span * sigma,
            np.where(running, self.span * d1 * self.rate, 0.0),
            np.where(running, self.span * d2 * self.rate**2, 0.0),
            np.where(running, self.span * d3 * self.rate**3, 0.0),
        )

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        q, dq, ddq, _ = self._joint(s, side)
        return PathPoints(q, dq, ddq)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        return self._joint(s, side)[3]


@dataclass(frozen=True)
class JointLawTiming(ConstantSpeedTiming):
    """s = t / T along a ``JointLawPath``, with the limit that set the slowest joint's duration."""

    binding: Binding | None = None


def _peaks(profile: NormalizedProfile) -> tuple[np.ndarray, np.ndarray]:
    """The peaks of |sigma'|, |sigma''| and |sigma'''| over [0, 1], and the tau of each."""
    tau = np.union1d(np.linspace(0.0, 1.0, PEAK_SAMPLES), profile.knots())
    values = np.abs(np.array(profile.derivatives(tau)[1:]))
    return values.max(axis=1), tau[values.argmax(axis=1)]


def own_durations(profile: NormalizedProfile, span: np.ndarray, limits: JointLimits, kinds: tuple[str, ...], joint_names: tuple[str, ...]) -> tuple[np.ndarray, list[str]]:
    """Each joint's shortest duration T_j (s) for moving by ``span`` (n_dof,) under the
    velocity, acceleration and jerk limits among ``kinds``, and the kind that sets each one."""
    peaks = _peaks(profile)[0]
    distance = np.abs(np.asarray(span, dtype=float))
    candidates = []
    with np.errstate(divide="ignore", invalid="ignore"):
        for order, kind in enumerate(("velocity", "acceleration", "jerk")):
            if kind in kinds:
                value = np.nan_to_num(distance * peaks[order] / getattr(limits, kind), nan=0.0) ** (1.0 / (order + 1))
                candidates.append((kind, value))
    if not candidates:
        raise Conflicting("law.synchronization", "none", ("constraints",), rule="unsynchronized_needs_a_limit")
    stacked = np.array([value for _, value in candidates])
    durations = stacked.max(axis=0)
    unbounded = np.flatnonzero((distance > 0) & (durations == 0.0))
    if unbounded.size:
        raise Conflicting("law.synchronization", "none", ("constraints", "limits"), rule="unsynchronized_joint_unlimited",
                          joint_name=joint_names[unbounded[0]])
    return durations, [candidates[i][0] for i in stacked.argmax(axis=0)]


def _torque_ratio(robot: Robot, path: JointLawPath, limits: JointLimits) -> tuple[float, float, int]:
    """Largest |torque| / limit over samples of the move, and its s and joint."""
    s = np.union1d(np.linspace(0.0, 1.0, TORQUE_SAMPLES), path.knots)
    points = path.evaluate(s)
    speed = 1.0 / path.total
    tau = robot.inverse_dynamics(points.q, points.dq * speed, points.ddq * speed**2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.nan_to_num(np.abs(tau) / limits.torque, nan=0.0)
    sample, joint = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    return float(ratio[sample, joint]), float(s[sample]), int(joint)


def _too_short(robot: Robot, profile: NormalizedProfile, durations: np.ndarray, setting: list[str], factor: float) -> LimitExceeded:
    """The limit most exceeded when every joint's own duration (``durations``, s, each set by
    the kind ``setting`` names) is shortened by ``factor`` < 1: a joint set by a limit of order k
    (velocity 1, acceleration 2, jerk 3) is over it by factor^-k, so the highest order among the
    joints is most exceeded, on the slowest joint it sets; its limits of lower order less."""
    moving = np.flatnonzero(durations > 0)
    order = max(ORDERS[setting[j]] for j in moving)
    joint = max((j for j in moving if ORDERS[setting[j]] == order), key=lambda j: durations[j])
    kind, ratio = setting[joint], float(factor ** -order)
    s = float(_peaks(profile)[1][order - 1]) * durations[joint] / durations.max()
    return LimitExceeded(
        f"the {profile.name} law exceeds the {kind} limit of joint {robot.joint_names[joint]!r} by "
        f"{100 * (ratio - 1):.2f} % at s = {s:.4f}: the duration is too short",
        s=s, joint=robot.joint_names[joint], limit=kind, ratio=ratio, method=profile.name,
    )


def unsynchronized_trajectory(
    robot: Robot,
    start: np.ndarray,
    goal: np.ndarray,
    profile: NormalizedProfile,
    limits: JointLimits,
    kinds: tuple[str, ...],
    duration: float | None,
    deadline: Deadline = NO_DEADLINE,
) -> tuple[JointLawPath, ConstantSpeedTiming]:
    """The non-normalized move from ``start`` to ``goal`` (n_dof,) with ``profile`` on every
    joint: each joint in its own shortest duration (stretched together by torque, or to the
    given ``duration`` of the slowest joint).

    Raises:
        InvalidRequest: no velocity, acceleration or jerk limit sets a moving joint's duration.
        InfeasiblePath: no common stretch brings the torques within their limits.
        BudgetExceeded: ``deadline`` passed.
    """
    span = np.asarray(goal, dtype=float) - np.asarray(start, dtype=float)
    durations, setting = own_durations(profile, span, limits, kinds, robot.joint_names)
    slowest = int(np.argmax(durations))

    def path(k):
        return JointLawPath(start, goal, profile, durations * k)

    peak_at = float(_peaks(profile)[1][ORDERS[setting[slowest]] - 1])
    binding: Binding | None = Binding(setting[slowest], robot.joint_names[slowest], peak_at)
    factor = 1.0
    if duration is not None:
        factor, binding = duration / durations[slowest], None
        if factor < 1.0 - SHORTER:
            raise _too_short(robot, profile, durations, setting, factor)
    elif "torque" in kinds and _torque_ratio(robot, path(1.0), limits)[0] > 1.0:
        low, high = 1.0, 2.0
        for _ in range(60):
            deadline.check()
            if _torque_ratio(robot, path(high), limits)[0] <= 1.0:
                break
            low, high = high, 2.0 * high
        else:
            raise InfeasiblePath("no common stretch of the joints' own durations holds the torque limits")
        for _ in range(40):
            deadline.check()
            middle = 0.5 * (low + high)
            low, high = (low, middle) if _torque_ratio(robot, path(middle), limits)[0] <= 1.0 else (middle, high)
        factor = high
        _, s, joint = _torque_ratio(robot, path(high), limits)
        binding = Binding("torque", robot.joint_names[joint], s)
    result = path(factor)
    return result, JointLawTiming(result.total, result.knots, binding)
