"""Each arm's time-optimal motion along its own path, and the two arms timed together along a
coordination curve, on one clock.

Along a curve sigma -> (s1(sigma), s2(sigma)) arm i sits at q_i(s_i(sigma)), so with ' = d/dsigma

    dq_i/dsigma   = q_i'(s_i) s_i'
    d2q_i/dsigma2 = q_i''(s_i) s_i'^2 + q_i'(s_i) s_i''

and every limit of both arms is a row of the usual phase-plane form in (sigma-dot^2, sigma-ddot)
(Jeong & Lee eq. (3.6); ``toptraj.planners.constraints.path_constraints.grid_rows`` on these
composed derivatives). One time-optimal solve (TOPP-RA) over the stacked rows times the pair:
each arm is held by its own phase-plane bounds, and one waits or slows where the curve says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints, build_path_constraints, grid_rows, speed_bound
from toptraj.planners.coordination.cell import CELL_KINDS, Cell, CellArm
from toptraj.planners.coordination.curve import SmoothCurve
from toptraj.planners.errors import LimitExceeded
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.problem.bounded import check_stretches_bounded
from toptraj.planners.timing.base import AT_REST, TimeScaling
from toptraj.planners.timing.scaled import solve_well_scaled
from toptraj.planners.timing.toppra_method import ToppraMethod

#: Grid intervals of each time-optimal solve.
TIMING_GRID = 400


def _timing_grid(arm: CellArm, intervals: int) -> np.ndarray:
    """A uniform grid of s that holds the path's kinks and breaks."""
    return np.union1d(np.linspace(0.0, 1.0, intervals + 1), np.r_[arm.path.kinks, arm.path.breaks])


def solo_timing(
    arm: CellArm, kinds: tuple[str, ...], intervals: int = TIMING_GRID, deadline: Deadline = NO_DEADLINE, field: str = "arm",
) -> TimeScaling:
    """The arm's own time-optimal motion along its path, alone in the world (TOPP-RA).

    Raises:
        InvalidRequest: a stretch of the path that no limit of ``kinds`` bounds (rule
            "stretch_unbounded", ``toptraj.planners.problem.bounded``; ``field`` names the arm).
    """
    from toptraj.planners.checks.gate import LIMIT_TOLERANCE, gated

    constraints = build_path_constraints(arm.path, arm.robot, arm.limits, kinds, _timing_grid(arm, intervals), deadline)
    check_stretches_bounded(constraints, arm.path, arm.robot, arm.limits, kinds, served=CELL_KINDS, field=field)
    # Through the limit gate, as a single arm's path: the grid refined where a limit is exceeded
    # between its points (else the whole cell's clock is slowed for it, ``limits.within_limits``)
    # and, for accuracy, where the error lies.
    try:
        timing, _, _ = gated(
            arm.robot, arm.path, ToppraMethod(), constraints, AT_REST, None, kinds, arm.limits, LIMIT_TOLERANCE, deadline,
        )
    except LimitExceeded:
        # The gate's refinements did not bring an excess between grid points within its
        # tolerance: the grid's own timing, the cell's clock then slowed where a limit needs it.
        timing = solve_well_scaled(ToppraMethod(), constraints, AT_REST, None, deadline)
    return timing  # type: ignore[return-value]


def _composed(arm: CellArm, s: np.ndarray, ds: np.ndarray, dds: np.ndarray):
    """q (n, n_dof) and its first two sigma-derivatives along the curve (module docstring)."""
    points = arm.path.evaluate(s)
    dq = points.dq * ds[:, None]
    return points.q, dq, points.ddq * (ds**2)[:, None] + points.dq * dds[:, None]


def pair_constraints(cell: Cell, curve: SmoothCurve, sigma: np.ndarray, deadline: Deadline = NO_DEADLINE) -> PathConstraints:
    """Both arms' limits along ``curve`` on the grid ``sigma`` (N + 1,): the rows of arm 0 then
    of arm 1 (joint indices of arm 1 offset by arm 0's joints)."""
    s, ds, dds = curve.evaluate(sigma)
    parts, sd_max, offset, names = [], np.full(len(sigma), np.inf), 0, []
    for index, arm in enumerate(cell.arms):
        q, dq, ddq = _composed(arm, s[:, index], ds[:, index], dds[:, index])
        arrays, rows = grid_rows(arm.robot, arm.limits, cell.kinds, q, dq, ddq, deadline)
        parts.append((arrays, tuple((kind, joint + offset) for kind, joint in rows)))
        if "velocity" in cell.kinds:
            sd_max = np.minimum(sd_max, speed_bound(arm.limits, dq)[0])
        names += [f"arms[{index}].{name}" for name in arm.robot.joint_names]
        offset += arm.robot.dof
    a, b, c, d, lower, upper = (np.hstack([arrays[k] for arrays, _ in parts]) for k in range(6))
    return PathConstraints(
        s=sigma,
        sd_max=sd_max,
        a=a,
        b=b,
        c=c,
        d=d,
        a_left=a,
        b_left=b,
        c_left=c,
        d_left=d,
        lower=lower,
        upper=upper,
        rows=parts[0][1] + parts[1][1],
        joint_names=tuple(names),
        knots=np.empty(0),
    )


def pair_timing(cell: Cell, curve: SmoothCurve, intervals: int = TIMING_GRID, deadline: Deadline = NO_DEADLINE) -> TimeScaling:
    """The time-optimal timing of sigma along ``curve`` under both arms' limits (TOPP-RA)."""
    constraints = pair_constraints(cell, curve, np.linspace(0.0, 1.0, intervals + 1), deadline)
    return solve_well_scaled(ToppraMethod(), constraints, AT_REST, None, deadline)  # type: ignore[return-value]


def _states(scaling: TimeScaling, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, sd, sdd of ``scaling`` at ``t``: at rest at s = 0 before it starts and at s = 1 after."""
    s, sd, sdd = scaling.at_times(t)
    moving = (t >= 0.0) & (t <= scaling.duration)
    return np.where(t < 0.0, 0.0, np.where(t > scaling.duration, 1.0, s)), np.where(moving, sd, 0.0), np.where(moving, sdd, 0.0)


@dataclass(frozen=True)
class SoloMotion:
    """An arm following its own time-optimal ``scaling``, started ``delay`` s late."""

    scaling: TimeScaling
    delay: float = 0.0

    @property
    def duration(self) -> float:
        return self.delay + self.scaling.duration

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, ds/dt (1/s), d2s/dt2 (1/s^2) at times ``t`` (n,)."""
        return _states(self.scaling, np.asarray(t, dtype=float) - self.delay)


@dataclass(frozen=True)
class CurveMotion:
    """Arm ``index`` along the coordination ``curve``, sigma timed by ``scaling``."""

    scaling: TimeScaling
    curve: SmoothCurve
    index: int

    @property
    def duration(self) -> float:
        return self.scaling.duration

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, ds/dt (1/s), d2s/dt2 (1/s^2) at times ``t`` (n,) (chain rule through sigma)."""
        sigma, sigma_d, sigma_dd = _states(self.scaling, np.asarray(t, dtype=float))
        s, ds, dds = self.curve.evaluate(sigma)
        i = self.index
        return s[:, i], ds[:, i] * sigma_d, ds[:, i] * sigma_dd + dds[:, i] * sigma_d**2


@dataclass(frozen=True)
class Schedule:
    """The arms' motions on one clock, the clock slowed by ``stretch`` (>= 1: at time t each
    arm is where its motion is at t / stretch), and how the schedule was found (``kind``)."""

    motions: tuple[SoloMotion | CurveMotion, ...]
    kind: str
    stretch: float = 1.0

    @property
    def duration(self) -> float:
        return self.stretch * max(motion.duration for motion in self.motions)

    def states(self, cell: Cell, t: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Each arm's q, qd, qdd (n, n_dof) at times ``t`` (n,), rad, rad/s, rad/s^2."""
        out = []
        for arm, motion in zip(cell.arms, self.motions):
            s, sd, sdd = motion.at(np.asarray(t, dtype=float) / self.stretch)
            sd, sdd = sd / self.stretch, sdd / self.stretch**2
            points = arm.path.evaluate(s)
            out.append((points.q, points.dq * sd[:, None], points.dq * sdd[:, None] + points.ddq * (sd**2)[:, None]))
        return out

    def path_parameters(self, t: np.ndarray) -> np.ndarray:
        """(s1, s2) at times ``t`` (n,): shape (n, 2)."""
        return np.column_stack([motion.at(np.asarray(t, dtype=float) / self.stretch)[0] for motion in self.motions])
