"""The jerk-limited timing's polish: the grid solution refined in time, as segments of constant
path jerk whose durations and jerks are free (``JerkSegmentsTiming``).

The grid solution (``toptraj.planners.timing.jerk.method``) holds u = sdd piecewise linear in s, which
follows a phase of constant jerk (u^2 linear in sd) only approximately, and its switches fall
between grid points. Time-optimal jerk-limited motions are made of arcs on which the jerk is at
a bound or a limit holds with equality; where the limits do not change along the path (a
straight joint line under joint limits) every arc has constant path jerk, and the optimum is a
handful of such segments with free switching times (Berscheid & Kroeger's seven phases). The
polish takes the grid solution's phases (runs of intervals whose path jerk has one sign, or is
near zero), one segment each, and solves

    minimize  sum tau_k   over the durations tau_k >= 0 and jerks sigma_k,
    such that the motion reaches s = 1 at the end state, and every limit holds at check points
              of every segment (its ends, quarters, and the extremum of sd),

by sequential linear programming (HiGHS) in a trust region, each step corrected back onto the
limits it makes active, with exact derivatives of the states and the limits' path dependence by
finite differences. The result is checked on a dense resampling of
every segment against the same limits; points found above a limit become check points and the
problem is solved again. It is kept when it holds the limits and is shorter than the grid
solution; for limits constant along the path it is the exact optimum.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.timing.jerk.segments import JerkSegmentsTiming, segment_starts
from toptraj.planners.timing.jerk.trust_region import solve_penalized

if TYPE_CHECKING:
    from toptraj.planners.timing.jerk.scaling import JerkTimeScaling

#: Most segments polished: a time-optimal motion under limits that do not change along the
#: path has at most seven; many more phases mean limits that change along it, where segments
#: of constant jerk do not beat the grid solution and the polish would only cost time.
MAX_SEGMENTS = 9
#: Most linear programs of one polish.
MAX_ITERATIONS = 60
#: LPs after which a polish still far from feasible is abandoned.
GIVE_UP_AFTER = 10
#: Check points per segment, as fractions of its duration (the extremum of sd is added).
CHECK_FRACTIONS = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
#: Relative excess over a limit accepted on the dense check of the polished motion.
TOLERANCE = 1e-7
#: Rounds of adding check points where the dense check finds a limit exceeded.
ROUNDS = 3
#: States per segment in the polish's own dense check.
DENSE_FRACTIONS = np.linspace(0.0, 1.0, 65)
#: Runs of grid intervals shorter than these fractions of the duration join the run before
#: them, one segmentation per entry, tried in turn: the grid solution overshoots the end of a
#: ramp of the acceleration by a short run of the other sign (about 1 % of the duration on the
#: default grid), which the coarse segmentation removes; the fine one keeps short phases a
#: profile may really have.
MERGE_FRACTIONS = (0.02, 1e-3)


def phases(grid_timing: JerkTimeScaling, merge_below: float = 1e-3) -> tuple[np.ndarray, np.ndarray] | None:
    """Initial durations and jerks of the segments: the runs of grid intervals whose path jerk
    is above a quarter of its largest magnitude, below minus that, or in between; runs shorter
    than ``merge_below`` times the duration join the run before them. ``None`` when there are
    more than ``MAX_SEGMENTS``."""
    times = grid_timing.interval_times
    middle = 0.5 * (grid_timing.s[:-1] + grid_timing.s[1:])
    interval = np.arange(len(times))
    _, _, sddd = grid_timing._state(interval, middle - grid_timing.s[:-1])
    scale = np.abs(sddd).max()
    if not np.isfinite(scale) or scale == 0.0:
        return None
    level = np.where(sddd > 0.25 * scale, 1, np.where(sddd < -0.25 * scale, -1, 0))
    breaks = np.flatnonzero(np.diff(level)) + 1
    runs = np.split(interval, breaks)
    total = times.sum()
    merged: list[np.ndarray] = []
    for run in runs:
        if merged and times[run].sum() < merge_below * total:
            merged[-1] = np.concatenate([merged[-1], run])
        else:
            merged.append(run)
    if len(merged) > 1 and times[merged[0]].sum() < merge_below * total:
        merged[1] = np.concatenate([merged[0], merged[1]])
        merged.pop(0)
    if len(merged) > MAX_SEGMENTS:
        return None
    u = grid_timing.u
    durations = np.array([times[run].sum() for run in merged])
    jerks = np.array([(u[run[-1] + 1] - u[run[0]]) / tau for run, tau in zip(merged, durations)])
    return durations, jerks


class _Checks:
    """The limits of ``constraints`` at states of the segments: values >= 0 where they hold,
    each scaled by its limit, and their derivatives."""

    def __init__(self, constraints: PathConstraints):
        self.constraints = constraints
        assert constraints.jerk is not None  # polished only where jerk is limited
        dq, _, _, limit = constraints.jerk
        self.jerk_joints = np.flatnonzero(np.isfinite(limit))
        self.jerk_limit = limit[self.jerk_joints]

    def _coefficients(self, s):
        assert self.constraints.evaluate is not None  # polished only where the rows can be evaluated
        rows = self.constraints.evaluate(np.clip(s, 0.0, 1.0))
        assert rows.jerk is not None
        dq, ddq, dddq, _ = rows.jerk
        j = self.jerk_joints
        return rows.sd_max, rows.a, rows.b, rows.c, rows.d, rows.lower, rows.upper, dq[:, j], ddq[:, j], dddq[:, j]

    def values(self, s, v, a, sigma, derivatives: bool = False):
        """Scaled slacks (n_points, n_checks), and with ``derivatives`` their derivatives with
        respect to s, v, a and sigma (each of the same shape)."""
        coefficients = self._coefficients(s)
        result = self._slacks(coefficients, s, v, a, sigma)
        if not derivatives:
            return result[0]
        step = 1e-7
        ahead = self._slacks(self._coefficients(s + step), s + step, v, a, sigma)[0]
        behind = self._slacks(self._coefficients(s - step), s - step, v, a, sigma)[0]
        inside = (s + step <= 1.0) & (s - step >= 0.0)
        d_s = np.where(
            inside[:, None], (ahead - behind) / (2 * step),
            np.where((s + step <= 1.0)[:, None], (ahead - result[0]) / step, (result[0] - behind) / step),
        )
        return result[0], d_s, result[1], result[2], result[3]

    def _slacks(self, coefficients, s, v, a, sigma):
        sd_max, A, B, C, D, lower, upper, dq, ddq, dddq = coefficients
        columns, d_v, d_a, d_sigma = [], [], [], []
        finite = np.isfinite(sd_max)
        bound = np.where(finite, sd_max, 1.0)
        columns.append(np.where(finite, 1.0 - v / bound, 1.0)[:, None])
        d_v.append(np.where(finite, -1.0 / bound, 0.0)[:, None])
        d_a.append(np.zeros_like(columns[-1]))
        d_sigma.append(np.zeros_like(columns[-1]))
        if A.shape[1]:
            value = A * a[:, None] + B * (v * v)[:, None] + C + D * v[:, None]
            dv = 2.0 * B * v[:, None] + D
            for bound_, sign in ((upper, 1.0), (lower, -1.0)):
                finite = np.isfinite(bound_)
                scale = np.where(finite, np.abs(bound_), 1.0)
                scale = np.where(scale > 0, scale, 1.0)
                columns.append(np.where(finite, sign * (bound_ - value) / scale, 1.0))
                d_v.append(np.where(finite, -sign * dv / scale, 0.0))
                d_a.append(np.where(finite, -sign * A / scale, 0.0))
                d_sigma.append(np.zeros_like(value))
        if self.jerk_limit.size:
            value = dq * sigma[:, None] + 3.0 * ddq * (v * a)[:, None] + dddq * (v**3)[:, None]
            dv = 3.0 * ddq * a[:, None] + 3.0 * dddq * (v * v)[:, None]
            da = 3.0 * ddq * v[:, None]
            for sign in (1.0, -1.0):
                columns.append(1.0 - sign * value / self.jerk_limit)
                d_v.append(-sign * dv / self.jerk_limit)
                d_a.append(-sign * da / self.jerk_limit)
                d_sigma.append(-sign * dq / self.jerk_limit)
        return tuple(np.concatenate(part, axis=1) for part in (columns, d_v, d_a, d_sigma))


def _points(durations, jerks, start, checks):
    """States at the check points ``checks`` = (segment index, fraction) and their
    derivatives with respect to (durations, jerks): s, v, a, sigma (n,), and D (n, 3, 2M)."""
    M = len(durations)
    starts = segment_starts(durations, jerks, start)
    # Derivatives of each segment's start state with respect to all variables.
    D = np.zeros((M + 1, 3, 2 * M))
    for k in range(M):
        tau, sigma = durations[k], jerks[k]
        transfer = np.array([[1.0, tau, tau**2 / 2], [0.0, 1.0, tau], [0.0, 0.0, 1.0]])
        D[k + 1] = transfer @ D[k]
        s, v, a = starts[k]
        D[k + 1, :, k] += (v + a * tau + sigma * tau**2 / 2, a + sigma * tau, sigma)
        D[k + 1, :, M + k] += (tau**3 / 6, tau**2 / 2, tau)
    segment, fraction = checks
    tau, sigma = durations[segment], jerks[segment]
    s0, v0, a0 = starts[segment].T
    # A negative fraction stands for the extremum of sd in the segment, t = -a0 / sigma,
    # clipped into it (the largest speed of a segment lies there or at an end).
    vertex = fraction < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        free = np.where(sigma != 0, -a0 / sigma, 0.0)
    inside = vertex & (free > 0.0) & (free < tau)
    at_end = vertex & (free >= tau)
    t = np.where(inside, free, np.where(at_end, tau, np.where(vertex, 0.0, fraction * tau)))
    phi = np.where(at_end, 1.0, np.where(vertex, 0.0, fraction))
    s = s0 + v0 * t + a0 * t**2 / 2 + sigma * t**3 / 6
    v = v0 + a0 * t + sigma * t**2 / 2
    a = a0 + sigma * t
    transfer = np.zeros((len(t), 3, 3))
    transfer[:, 0, 0] = transfer[:, 1, 1] = transfer[:, 2, 2] = 1.0
    transfer[:, 0, 1] = transfer[:, 1, 2] = t
    transfer[:, 0, 2] = t**2 / 2
    Dp = np.einsum("nij,njk->nik", transfer, D[segment])
    rows = np.arange(len(t))
    rate = np.column_stack([v, a, sigma])  # d(s, v, a)/dt
    Dp[rows, :, segment] += phi[:, None] * rate
    Dp[rows, :, M + segment] += np.column_stack([t**3 / 6, t**2 / 2, t])
    if inside.any():
        # The extremum moves with the variables: dt = -(da0 + t dsigma) / sigma.
        moving = np.flatnonzero(inside)
        dt = -D[segment[moving], 2, :] / sigma[moving, None]
        dt[np.arange(moving.size), M + segment[moving]] -= t[moving] / sigma[moving]
        Dp[moving] += rate[moving, :, None] * dt[:, None, :]
    return s, v, a, sigma, Dp, starts, D


def polish(
    constraints: PathConstraints, grid_timing: JerkTimeScaling, sd_start: float, sd_end: float, deadline: Deadline
) -> JerkSegmentsTiming | None:
    """The polished timing (``JerkSegmentsTiming``), or ``None`` when the polish does not find a
    motion that holds the limits and is shorter than ``grid_timing``: each segmentation of
    ``MERGE_FRACTIONS`` polished in turn, the shortest result kept."""
    if not constraints.can_refine:
        return None
    best = None
    tried: list[np.ndarray] = []
    for merge_below in MERGE_FRACTIONS:
        initial = phases(grid_timing, merge_below)
        if initial is None or any(len(initial[0]) == len(seen) for seen in tried):
            continue
        tried.append(initial[0])
        result = _polished(constraints, grid_timing, initial, sd_start, sd_end, deadline)
        if result is not None and (best is None or result.duration < best.duration):
            best = result
    return best


def _polished(constraints, grid_timing, initial, sd_start: float, sd_end: float, deadline: Deadline):
    """The polish from the segments ``initial`` (durations, jerks), or ``None``."""
    durations, jerks = initial
    M = len(durations)
    start = (0.0, sd_start, 0.0)
    checks_model = _Checks(constraints)
    segment = np.repeat(np.arange(M), len(CHECK_FRACTIONS) + 1)
    fraction = np.tile(np.append(CHECK_FRACTIONS, -1.0), M)
    scales = np.concatenate([np.full(M, grid_timing.duration / M), np.full(M, max(np.abs(jerks).max(), 1e-12))])
    end_scale = np.array([1.0, max(grid_timing.sd.max(), 1e-12), max(np.abs(grid_timing.u).max(), 1e-12)])
    z = np.concatenate([durations, jerks]) / scales
    for _ in range(ROUNDS + 1):
        checks = (segment, fraction)

        def evaluate(z, checks=checks):
            deadline.check()
            tau, sigma = np.maximum(z[:M] * scales[:M], 0.0), z[M:] * scales[M:]
            s, v, a, sig, Dp, starts, D = _points(tau, sigma, start, checks)
            h = (starts[-1] - np.array([1.0, sd_end, 0.0])) / end_scale
            H = D[-1] * scales[None, :] / end_scale[:, None]
            g, d_s, d_v, d_a, d_sigma = checks_model.values(s, v, a, sig, derivatives=True)
            sigma_d = np.zeros((len(s), 2 * M))
            sigma_d[np.arange(len(s)), M + checks[0]] = 1.0
            G = (
                d_s[:, :, None] * Dp[:, None, 0, :]
                + d_v[:, :, None] * Dp[:, None, 1, :]
                + d_a[:, :, None] * Dp[:, None, 2, :]
                + d_sigma[:, :, None] * sigma_d[:, None, :]
            )
            return h, H, g.ravel(), G.reshape(-1, 2 * M) * scales[None, :]

        z = solve_penalized(z, evaluate, M, MAX_ITERATIONS, GIVE_UP_AFTER)
        if z is None:
            return None
        durations, jerks = np.maximum(z[:M] * scales[:M], 0.0), z[M:] * scales[M:]
        end = segment_starts(durations, jerks, start)[-1]
        if np.abs((end - np.array([1.0, sd_end, 0.0])) / end_scale).max() > 1e-8:
            return None
        # s is linear in the jerks from a start at rest: scale them to end exactly at s = 1.
        if sd_start == 0.0 and end[0] > 0:
            jerks = jerks / end[0]
        timing = JerkSegmentsTiming(durations, jerks, start)
        worst = _dense_excess(checks_model, timing)
        if worst is None:
            return timing if timing.duration < grid_timing.duration else None
        # Check where the dense check found a limit exceeded, and solve again.
        segment = np.concatenate([segment, worst[0]])
        fraction = np.concatenate([fraction, worst[1]])
    return None


def _dense_excess(checks_model: _Checks, timing: JerkSegmentsTiming):
    """(segments, fractions) of the dense states where a limit is exceeded by more than
    ``TOLERANCE`` (the worst state of each such segment), or ``None`` when none is."""
    M = len(timing.durations)
    segment = np.repeat(np.arange(M), len(DENSE_FRACTIONS))
    fraction = np.tile(DENSE_FRACTIONS, M)
    s, v, a, sigma, _, _, _ = _points(timing.durations, timing.jerks, timing.start, (segment, fraction))
    slack = checks_model.values(s, v, a, sigma).min(axis=1)
    bad = slack < -TOLERANCE
    if not bad.any():
        return None
    worst_segments, worst_fractions = [], []
    for k in np.unique(segment[bad]):
        mine = np.flatnonzero((segment == k) & bad)
        pick = mine[np.argmin(slack[mine])]
        worst_segments.append(k)
        worst_fractions.append(fraction[pick])
    return np.array(worst_segments), np.array(worst_fractions)
