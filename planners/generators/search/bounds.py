"""Lower bounds on the motion time along grid paths (Jeong & Lee section 2.4, after Shiller &
Dubowsky 1991), each a bound on the next, so that t1 <= t2 <= t3 <= t4 = t_opt:

1. maximum speed (eq. 2.6): t1 = sum of segment lengths / V_max, V_max the highest joint-space
   speed on the velocity limit curve of any piece of the graph (so the bound holds for every
   grid path, not only for a representative one), each interval's length read as its
   parameter length over the joint-space speed V_max allows at its ends;
2. velocity limit (eq. 2.7): t2 = integral of d lambda / lambda-dot_m, the path following its
   velocity limit curve (the maximum velocity curve of the phase plane: velocity, acceleration
   and torque limits);
3. maximum acceleration, velocity limit, maximum deceleration (eq. 2.8): the speed no higher
   than the maximum-acceleration curve from rest at the start, the velocity limit curve, and
   the maximum-deceleration curve into rest at the goal;
4. t4 = t_opt: the phase-plane timing of the grid path (``toptraj.planners.timing.phase_plane.method``).

All four are computed in the discretization the phase-plane method uses on the same grid (x =
sd^2 linear in the curve's parameter over each interval, every limit row held at both ends of it;
``toptraj.planners.constraints.admissible_kernels.interval_bounds`` gives the rows of each interval as bounds on u), so each is
a lower bound on the discrete t4 of that grid, which ``grid_path_time`` computes with the
phase-plane method itself. Viscous friction, which the phase-plane method linearizes, is relaxed
to the widest bounds it can take below the first-order speed bound. t1 and t2 add up over the
pieces of a grid path; t3 over a partial path uses the forward curve only (the speed at its cut
is not known), the complete path's both. The rows are computed once at each of a piece's
INTERVALS + 1 samples (an interval's end is the next one's start), the samples of a chunk of
pieces laid out as one grid for the phase-plane kernels.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.constraints.admissible_kernels import NOTHING_BEFORE, NOTHING_KEPT, interval_bounds, point_bounds
from toptraj.planners.constraints.path_constraints import build_path_constraints, grid_rows, speed_bound
from toptraj.planners.generators.search.curve import GridSplinePath
from toptraj.planners.generators.search.pieces import INTERVALS, Pieces
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.robots import JointLimits, Robot

if TYPE_CHECKING:
    from toptraj.planners.execution.deadline import Deadline

_INF = np.inf
#: Rows of limits evaluated between two deadline checks.
CHUNK = 20_000


@dataclass(frozen=True)
class PieceBounds:
    """The limits of every interval of every piece as bounds on the path acceleration u, in
    the curve's parameter u (x = u-dot^2, 1/s^2).

    Attributes:
        ds: Interval lengths, shape (I,).
        p, q, r: ``p + q x <= u <= r + q x`` per row of each interval (both ends), shape (I, 2m).
        cap_start: Largest admissible x at each interval's start, shape (I,); -1 where none.
        cap_end: Largest admissible x at each interval's end (its rows there and the speed
            bound), shape (I,).
        t1, t2: Per piece, its time at the joint-space speed V_max and along the velocity limit
            curve (s), shape (K,); ``inf`` for a piece no motion can follow.
        v_max: The highest speed on any piece's velocity limit curve (joint units / s).
        feasible: Per piece, whether some motion can follow it (every interval admits a state).
    """

    ds: np.ndarray
    p: np.ndarray
    q: np.ndarray
    r: np.ndarray
    cap_start: np.ndarray
    cap_end: np.ndarray
    t1: np.ndarray
    t2: np.ndarray
    v_max: float
    feasible: np.ndarray


def _rows(robot: Robot, limits: JointLimits, kinds, q, dq, ddq):
    """Rows ``a u + b x + c in [lower, upper]`` at configurations q with parameter derivatives
    dq, ddq (each (k, n)), viscous friction relaxed below the speed bound, and that bound
    x_bound (k,): the rows of ``toptraj.planners.constraints.path_constraints.build_path_constraints``."""
    x_bound = np.full(len(q), _INF)
    if "velocity" in kinds:
        x_bound = speed_bound(limits, dq)[0] ** 2
    (a, b, c, d, lower, upper), _ = grid_rows(robot, limits, kinds, q, dq, ddq)
    if np.any(d != 0.0):
        speed = np.sqrt(x_bound)[:, None]
        with np.errstate(invalid="ignore"):
            term_high = np.where(d != 0.0, np.maximum(d * speed, 0.0), 0.0)
            term_low = np.where(d != 0.0, np.minimum(d * speed, 0.0), 0.0)
        lower = lower - np.nan_to_num(term_high, nan=_INF)
        upper = upper - np.nan_to_num(term_low, nan=-_INF)
    return np.ascontiguousarray(a), np.ascontiguousarray(b), np.ascontiguousarray(c), d, lower, upper, x_bound


def _samples(pieces: Pieces, rows: slice) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, dq, ddq (c (INTERVALS + 1), n_dof) at the INTERVALS + 1 samples of the pieces
    ``rows``, piece after piece (views of ``Pieces.q``, ``dq``, ``ddq``)."""
    n = pieces.q.shape[2]
    return pieces.q[rows].reshape(-1, n), pieces.dq[rows].reshape(-1, n), pieces.ddq[rows].reshape(-1, n)


def piece_bounds(pieces: Pieces, robot: Robot, limits: JointLimits, kinds: tuple[str, ...], deadline: Deadline) -> PieceBounds:
    """The bounds of every piece (t1, t2 and the arrays t3 runs on). The limits' rows are
    computed once per sample of a piece (``_samples``), a chunk of ``CHUNK`` intervals at a
    time."""
    count = len(pieces.ds)
    p = q = r = np.empty((count, 0))
    cap_start, cap_end = np.empty(count), np.empty(count)
    per_chunk = max(1, CHUNK // INTERVALS)
    for begin in range(0, len(pieces), per_chunk):
        deadline.check()
        chunk = slice(begin, min(begin + per_chunk, len(pieces)))
        rows = slice(chunk.start * INTERVALS, chunk.stop * INTERVALS)
        part = _interval_arrays(pieces.ds[rows], _rows(robot, limits, kinds, *_samples(pieces, chunk)))
        if begin == 0:  # the rows' count is known now: the arrays filled in place, chunk by chunk
            p, q, r = (np.empty((count, part[0].shape[1])) for _ in range(3))
        p[rows], q[rows], r[rows], cap_start[rows], cap_end[rows] = part
    owner = np.repeat(np.arange(len(pieces)), np.diff(pieces.first))
    last = np.zeros(count, dtype=bool)
    last[pieces.first[1:] - 1] = True
    following = np.append(cap_start[1:], _INF)
    end_cap = np.where(last, cap_end, np.minimum(cap_end, following))
    with np.errstate(invalid="ignore", divide="ignore"):
        interval_t2 = 2.0 * pieces.ds / (np.sqrt(np.maximum(cap_start, 0.0)) + np.sqrt(np.maximum(end_cap, 0.0)))
    interval_t2 = np.where(np.isnan(interval_t2), _INF, interval_t2)
    bad = (cap_start < 0.0) | (cap_end < 0.0)
    feasible = np.bincount(owner, weights=bad, minlength=len(pieces)) == 0
    t2 = np.bincount(owner, weights=np.where(bad, 0.0, interval_t2), minlength=len(pieces))
    t2 = np.where(feasible, t2, _INF)
    speeds = np.linalg.norm(pieces.dq, axis=2)  # (K, INTERVALS + 1)
    speed0, speed1 = speeds[:, :-1].ravel(), speeds[:, 1:].ravel()
    fast = np.concatenate([speed0 * np.sqrt(np.maximum(cap_start, 0.0)), speed1 * np.sqrt(np.maximum(cap_end, 0.0))])
    v_max = float(fast.max()) if fast.size else _INF
    if not np.isfinite(v_max) or v_max >= 1e6:
        v_max = _INF
    with np.errstate(invalid="ignore", divide="ignore"):
        interval_t1 = 2.0 * pieces.ds / (v_max / speed0 + v_max / speed1)
    interval_t1 = np.nan_to_num(interval_t1, nan=0.0, posinf=0.0)
    t1 = np.bincount(owner, weights=interval_t1, minlength=len(pieces))
    return PieceBounds(pieces.ds, p, q, r, cap_start, cap_end, np.where(feasible, t1, _INF), t2, v_max, feasible)


def _interval_arrays(ds, sampled):
    """p, q, r (k, 2m), cap_start, cap_end (k,) of the k intervals of k / INTERVALS pieces
    (lengths ``ds`` (k,)) from the rows ``sampled`` (``_rows``) at the pieces' samples
    (``_samples``), through the phase-plane kernels: the samples laid out as one grid, a piece's
    INTERVALS intervals followed by a gap of length 1 to the next piece's first sample, whose
    bounds are dropped."""
    a, b, c, _, lower, upper, x_bound = sampled
    k, m = len(ds), a.shape[1]
    pieces = k // INTERVALS
    width = INTERVALS + 1
    starts = (np.arange(pieces * width).reshape(pieces, width)[:, :-1]).ravel()  # each interval's first sample
    ends = starts + 1
    if m == 0:
        empty = np.zeros((k, 0))
        return empty, empty, empty, np.where(np.isfinite(x_bound[starts]), x_bound[starts], _INF), np.where(np.isfinite(x_bound[ends]), x_bound[ends], _INF)
    # s: a piece's samples at s_0 + j ds, the next piece's first one step of 1 beyond its last
    steps = np.ones(pieces * width - 1)
    steps[starts[starts < len(steps)]] = ds
    s = np.concatenate([[0.0], np.cumsum(steps)])
    zero = np.zeros_like(a)
    p, q, r, _, x_high, _ = interval_bounds(s, a, b, c, zero, a, b, c, zero, lower, upper, x_bound, x_bound, False, False, NOTHING_KEPT, NOTHING_BEFORE)
    cap = point_bounds(a, b, c, lower, upper, x_bound)[4]
    return p[starts], q[starts], r[starts], x_high[starts], cap[ends]


@njit(cache=True, nogil=True)
def _time(ds, x0, x1):  # pragma: no cover - compiled
    """Time over an interval of length ds with x = sd^2 linear from x0 to x1."""
    total = np.sqrt(max(x0, 0.0)) + np.sqrt(max(x1, 0.0))
    if total <= 0.0:
        return _INF
    return 2.0 * ds / total


@njit(cache=True, nogil=True)
def _ahead(i, x, ds, q, r):  # pragma: no cover - compiled
    """The most x at the end of interval i from any start state x_i <= x, at maximum path
    acceleration: min over rows of 2 ds r_k + max(0, 1 + 2 ds q_k) x (each row's line through
    [0, x]; an upper bound also where a row's line falls)."""
    step = 2.0 * ds[i]
    reach = _INF
    for k in range(r.shape[1]):
        if r[i, k] < _INF:
            slope = 1.0 + step * q[i, k]
            value = step * r[i, k] + (slope if slope > 0.0 else 0.0) * x
            if value < reach:
                reach = value
    return reach if reach > 0.0 else 0.0


@njit(cache=True, nogil=True)
def forward_time(lo, hi, ds, q, r, cap_start, cap_end, x_in) -> tuple[float, float]:  # pragma: no cover - compiled
    """t3 over the intervals lo .. hi - 1 (one piece) entered with x at most ``x_in``: the time
    with x on the maximum-acceleration curve, capped by the velocity limit curve. Returns the
    time (s) and the bound on x at the piece's end."""
    x = min(x_in, cap_start[lo])
    total = 0.0
    for i in range(lo, hi):
        following = _ahead(i, x, ds, q, r)
        cap = cap_end[i]
        if i + 1 < hi and cap_start[i + 1] < cap:
            cap = cap_start[i + 1]
        if following > cap:
            following = cap
        total += _time(ds[i], x, following)
        x = following
    return total, x


@njit(cache=True, nogil=True)
def path_time(intervals, ds, p, q, r, cap_start, cap_end) -> float:  # pragma: no cover - compiled
    """t3 of a complete grid path over ``intervals`` (indices, in order), from rest to rest: x
    below the maximum-acceleration curve from the start, the velocity limit curve and the
    maximum-deceleration curve into the goal (eq. 2.8)."""
    n = intervals.shape[0]
    forward = np.empty(n + 1)
    backward = np.empty(n + 1)
    forward[0] = 0.0
    for j in range(n):
        i = intervals[j]
        cap = cap_end[i]
        if j + 1 < n and cap_start[intervals[j + 1]] < cap:
            cap = cap_start[intervals[j + 1]]
        x = min(forward[j], cap_start[i])
        following = _ahead(i, x, ds, q, r)
        forward[j + 1] = following if following < cap else cap
    backward[n] = 0.0
    for j in range(n - 1, -1, -1):
        i = intervals[j]
        step = 2.0 * ds[i]
        high = cap_start[i]
        if j > 0 and cap_end[intervals[j - 1]] < high:
            high = cap_end[intervals[j - 1]]
        for k in range(p.shape[1]):
            if p[i, k] > -_INF:
                slope = 1.0 + step * q[i, k]
                if slope > 0.0:
                    value = (backward[j + 1] - step * p[i, k]) / slope
                    if value < high:
                        high = value
        backward[j] = high if high > 0.0 else 0.0
    total = 0.0
    for j in range(n):
        x0 = min(forward[j], backward[j])
        x1 = min(forward[j + 1], backward[j + 1])
        total += _time(ds[intervals[j]], x0, x1)
    return total


def grid_path_time(points: np.ndarray, robot: Robot, limits: JointLimits, kinds: tuple[str, ...]) -> float:
    """t4 (s): the phase-plane method (``toptraj.planners.timing.phase_plane.method``, without refinement) on
    the curve of the grid path through ``points`` (``toptraj.planners.generators.search.curve``), on the grid of
    its pieces (``INTERVALS`` per span)."""
    curve = GridSplinePath(points)
    s = np.linspace(0.0, 1.0, curve.spans * INTERVALS + 1)
    constraints = build_path_constraints(curve, robot, limits, kinds, s)
    return PhasePlaneMethod(max_refinements=0).solve(constraints).duration
