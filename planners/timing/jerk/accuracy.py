"""How far the jerk-limited timing's grid solution lies from the optimum of its continuous
problem, estimated on a second grid (``toptraj.planners.timing.jerk.method``).

The grid solution converges to the optimum as the grid is refined; the difference between the
durations on two nested grids, T_coarse - T_fine, estimates the fine grid's error from above
wherever the error shrinks at least linearly with the interval (T_coarse - T* = 2 (T_fine - T*)
for first order, 4 times for second). That holds once the grid is fine enough: on the ur5
example the difference from 102 to 200 intervals (6.5e-4) is still below the error of the
200-interval solution (1.4e-3), while every later halving about halves it (8.4e-4, 3.4e-4,
1.7e-4, 7.8e-5); the method therefore refines its default grid once whatever the first
estimate (below ``ASYMPTOTIC_INTERVALS``), and states the difference between the last two grids.

Halving a grid (``refined``) keeps each interval at rest whole, as does the coarse grid of
``coarser`` (every other point of the fine one; the points toward an end at rest, which
resolve its constant-jerk phase, and the path's knots all kept). The coarser grid of each pair
is solved first; its solution is where the finer grid's first restriction is taken, which
saves most of the finer grid's LPs. Each sequence stops at a relative gain per LP below
``WARM_TOLERANCE`` (1e-5), slightly above its grid's fixed point (every step shortens the
motion); ``tests/planners/timing/test_jerk_gap.py`` checks the stated gap of the ur5 example against the optimum extrapolated
from grids four and eight times as fine, and ``benchmarks/jerk_gap.py`` on random paths.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.timing.base import Boundary

#: Ratio of successive differences of a first-order sequence: the slowest convergence assumed
#: where the differences shrink faster (before the grid is fine enough they may, and then
#: understate the error: ur5 example, 6.5e-4 then 8.4e-4, 3.4e-4 over each halving).
FIRST_ORDER_RATIO = 0.5
#: Largest ratio taken as observed: above it (convergence slower than order 1/3) the order is
#: not established, and the bound states this ratio's.
SLOWEST_RATIO = 0.8


def coarser(constraints: PathConstraints, original: np.ndarray) -> PathConstraints | None:
    """``constraints`` on every other point of their grid, the ends, the points inside the first
    and last interval of the ``original`` grid (the graded points toward an end at rest) and
    the path's knots kept; ``None`` when that drops no point or leaves fewer than six."""
    s = constraints.s
    keep = np.zeros(len(s), dtype=bool)
    keep[::2] = True
    keep[[0, -1]] = True
    if len(original) > 2:
        keep |= (s <= original[1]) | (s >= original[-2])
    if constraints.knots is not None and len(constraints.knots):
        keep |= np.isin(s, constraints.knots)
    if keep.all() or keep.sum() < 6:
        return None
    return kept(constraints, keep)


def kept(constraints: PathConstraints, keep: np.ndarray) -> PathConstraints:
    """``constraints`` on the grid points where ``keep`` (bool, one per point) holds."""

    def take(array):
        return None if array is None else np.asarray(array)[keep]

    same = constraints.a_left is constraints.a and constraints.b_left is constraints.b
    right = {name: take(getattr(constraints, name)) for name in ("a", "b", "c", "d")}
    left = (
        {f"{name}_left": right[name] for name in ("a", "b", "c", "d")}
        if same
        else {f"{name}_left": take(getattr(constraints, f"{name}_left")) for name in ("a", "b", "c", "d")}
    )
    jerk = None if constraints.jerk is None else (*(take(array) for array in constraints.jerk[:3]), constraints.jerk[3])
    jerk_left = None if constraints.jerk_left is None else tuple(take(array) for array in constraints.jerk_left)
    return dataclasses.replace(
        constraints,
        s=take(constraints.s),
        sd_max=take(constraints.sd_max),
        **right,
        **left,
        lower=take(constraints.lower),
        upper=take(constraints.upper),
        velocity_joint=take(constraints.velocity_joint),
        tool_bound=take(constraints.tool_bound),
        jerk=jerk,
        jerk_left=jerk_left,
        q=take(constraints.q),
    )


def refined(constraints: PathConstraints, boundary: Boundary) -> PathConstraints:
    """``constraints`` with every interval halved except one that starts or ends at rest: that
    interval holds the motion of constant path jerk from (to) rest exactly (u = 2 x / (3 s)),
    which intervals of linear u cannot follow (u grows as s^(1/3) there); halving it would
    leave half of that phase to them and lengthen the answer (0.24 % on the ur5 example, the
    error shrinking only as about h^(1/3) over further halvings), where the intervals away
    from rest converge at first order."""
    s = constraints.s
    middles = 0.5 * (s[:-1] + s[1:])
    keep = np.ones(len(middles), dtype=bool)
    keep[0] &= boundary.sd_start != 0.0
    keep[-1] &= boundary.sd_end != 0.0
    return constraints.with_points(middles[keep])


def relative_gap(coarse_duration: float, fine_duration: float) -> float:
    """|T_coarse - T_fine| / T_fine: the estimated relative error of the fine grid's duration
    (module docstring). A finer grid whose solution is longer shows an error of that size too
    (before the intervals at rest were kept whole, halving them did that, and a gap of 0 was
    stated 0.4 % above the optimum), so the difference counts whatever its sign."""
    return abs(coarse_duration - fine_duration) / fine_duration


def extrapolated_errors(durations: tuple[float, float, float]) -> tuple[float, float, float]:
    """The errors (s) of three durations on nested grids, each twice as fine as the last, from
    the ratio of their differences r = |d_2| / |d_1| (Richardson: a sequence converging as h^p
    has r = 2^-p and the error of its finest member r |d_2| / (1 - r)), r clipped to
    [``FIRST_ORDER_RATIO``, ``SLOWEST_RATIO``]: at least first order is assumed where the
    differences fall faster, and order 1/3 where they fall slower or grow (the order is then not
    established, and the bound is that of order 1/3)."""
    d1, d2 = abs(durations[0] - durations[1]), abs(durations[1] - durations[2])
    r = SLOWEST_RATIO if d1 == 0.0 else min(max(d2 / d1, FIRST_ORDER_RATIO), SLOWEST_RATIO)
    finest = d2 * r / (1.0 - r)
    return d1 + d2 + finest, d2 + finest, finest


def at_rest_halved(constraints: PathConstraints, ends: tuple[int, ...]) -> PathConstraints:
    """``constraints`` with the first (0) and last (-1) of their intervals listed in ``ends``
    halved: the intervals at rest that ``refined`` keeps whole, where no constant-jerk phase
    fills them (``toptraj.planners.timing.jerk.rest_phase.start_phase`` is infinite: no jerk limit
    binds there, the acceleration then jumps at rest in the optimum, and the first interval's
    linear u lags it by a time of order sqrt(h))."""
    s = constraints.s
    middles = [0.5 * (s[0] + s[1]) if end == 0 else 0.5 * (s[-2] + s[-1]) for end in ends]
    return constraints.with_points(np.unique(middles))
