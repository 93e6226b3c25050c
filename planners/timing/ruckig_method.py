"""``ruckig``: jerk-limited state-to-state motion with the ruckig library (Berscheid & Kroeger,
"Jerk-limited Real-time Trajectory Generation with Arbitrary Target States", RSS 2021).

The offline library plans from one state to another, without intermediate waypoints, so this
method times a straight joint-space move (two waypoints). Along q(s) = q0 + s (q1 - q0) every
joint moves in phase, and the joint limits become limits on s alone:
sd <= min_j v_j / |dq_j|, |sdd| <= min_j a_j / |dq_j|, |sddd| <= min_j j_j / |dq_j|. Ruckig's
time-optimal jerk-limited profile for s under those limits is the phase-synchronized multi-joint
motion (all joints reach their targets together along the line), and s in [0, 1] keeps every
joint between its two in-range waypoints. Torque is not a ruckig limit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, Result, Ruckig, Trajectory

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import Conflicting, InfeasiblePath, NotServed, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import AT_REST, Boundary, DenseStates, PathTiming, TimingMethod

#: Stand-in for an unlimited bound (ruckig needs finite numbers).
_UNLIMITED = 1e12


@dataclass(frozen=True)
class RuckigTiming(PathTiming):
    """s(t) from a one-dimensional ruckig trajectory: seven phases of constant jerk."""

    phase_durations: np.ndarray
    phase_jerks: np.ndarray
    trajectory: Trajectory

    @property
    def duration(self) -> float:
        return float(self.trajectory.duration)

    @property
    def optimality_gap(self) -> float:
        """0: the profile is the time-optimal one of its problem, found in closed form by ruckig
        (Berscheid & Kroeger 2021), not on a grid."""
        return 0.0

    @property
    def gap_basis(self) -> str:
        return "exact: ruckig's time-optimal jerk-limited profile for these limits, found in closed form (no grid)"

    def _states(self, t: np.ndarray):
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        s, sd, sdd = np.empty_like(t), np.empty_like(t), np.empty_like(t)
        for k, instant in enumerate(t):
            position, velocity, acceleration = self.trajectory.at_time(float(instant))
            s[k], sd[k], sdd[k] = position[0], velocity[0], acceleration[0]
        ends = np.cumsum(self.phase_durations)
        phase = np.clip(np.searchsorted(ends, t, side="right"), 0, len(ends) - 1)
        return s, sd, sdd, self.phase_jerks[phase]

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, sd, sdd, _ = self._states(t)
        return s, sd, sdd

    def dense_states(self, points_per_interval: int = 3) -> DenseStates:
        switches = np.concatenate(([0.0], np.cumsum(self.phase_durations)))
        t = np.union1d(np.linspace(0.0, self.duration, 2001), np.clip(switches, 0.0, self.duration))
        s, sd, sdd, sddd = self._states(t)
        return DenseStates(s, sd, sdd, sddd, np.zeros(len(t), dtype=bool))

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        t = np.linspace(0.0, self.duration, 2001)
        path_s, path_sd, _, _ = self._states(t)
        return np.interp(s, path_s, path_sd)


class RuckigMethod(TimingMethod):
    """Jerk-limited, time-optimal for its limits, between two states on a straight joint line."""

    name = "ruckig"
    kinds = frozenset({"velocity", "acceleration", "jerk"})
    required_kinds = frozenset({"jerk"})
    takes_acceleration_boundary = True
    two_waypoints_only = True
    continuous_acceleration = True
    pointwise = False  # one profile along the line, bounded by its tightest limit anywhere

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> RuckigTiming:
        assert constraints.jerk is not None  # ruckig requires the jerk rows (required_kinds)
        dq, ddq, _, jerk_limit = constraints.jerk
        if np.abs(ddq).max() > 1e-9 * max(1.0, np.abs(dq).max()):
            raise NotServed("waypoints", None, "ruckig", rule="ruckig_straight_only",
                            detail="ruckig times straight joint-space moves only: give exactly two waypoints")
        direction = np.abs(dq[0])
        moving = direction > 0
        with np.errstate(divide="ignore"):
            accel = min(
                (constraints.upper[0, column] / direction[joint]
                 for column, (kind, joint) in enumerate(constraints.rows) if kind == "acceleration"),
                default=np.inf,
            )
            jerk = float(np.min(jerk_limit[moving] / direction[moving]))
            accel = float(accel)
        speed = float(np.min(constraints.sd_max))
        if not (np.isfinite(speed) or np.isfinite(accel) or np.isfinite(jerk)):
            # Nothing bounds the move (an arm with torque limits only): ruckig would answer a
            # jump of the largest number it takes, not a motion.
            raise Conflicting("method", "ruckig", ("constraints", "limits"), rule="ruckig_needs_a_limit")
        inputs = InputParameter(1)
        inputs.current_position, inputs.target_position = [0.0], [1.0]
        inputs.current_velocity, inputs.target_velocity = [boundary.sd_start], [boundary.sd_end]
        inputs.current_acceleration = [boundary.sdd_start or 0.0]
        inputs.target_acceleration = [boundary.sdd_end or 0.0]
        inputs.max_velocity = [min(speed, _UNLIMITED)]
        inputs.max_acceleration = [min(accel, _UNLIMITED)]
        inputs.max_jerk = [min(jerk, _UNLIMITED)]
        inputs.min_position, inputs.max_position = [0.0], [1.0]
        trajectory = Trajectory(1)
        result = Ruckig(1).calculate(inputs, trajectory)
        if result == Result.ErrorPositionalLimits:
            raise InfeasiblePath(
                "ruckig cannot reach the goal without leaving the straight line between the waypoints "
                "(the boundary velocities overshoot it)"
            )
        if result not in (Result.Working, Result.Finished):
            raise TimingFailed(f"ruckig failed: {result.name}")
        profile = trajectory.profiles[0][0]
        return RuckigTiming(np.asarray(profile.t), np.asarray(profile.j), trajectory)
