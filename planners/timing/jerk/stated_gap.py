"""The gap ``jerk_limited`` states: the estimated relative distance of its answer from the
optimum of the continuous problem, from durations on nested grids
(``toptraj.planners.timing.jerk.accuracy``).

Two errors are estimated and added:

* the grid's: where the method refined its grid, the difference over its last halving (the
  one after the grid of ``ASYMPTOTIC_INTERVALS``, or beyond: the accuracy module's docstring);
  where it did not (a grid the caller named, or one already within ``GAP_TARGET``), from the
  second grid's, the answer's and the answer's halved (``refined``, solved for the estimate
  only), with the order their differences show (``extrapolated_errors``): the difference from
  the second grid alone equals the error only once the differences are first order, and
  understated it on the ur5 spline of the invariant test (named grid of 200 intervals: 4.64e-3
  stated, 4.70e-3 above the optimum extrapolated from grids 4 and 8 times as fine);
* the intervals at an end at rest that no constant-jerk phase fills (no jerk limit binds
  there): every grid keeps them whole, so the first estimate cannot see their error, which
  shrinks only as about sqrt(h) (the optimum's acceleration jumps at rest; the first
  interval's linear u lags it). They are halved twice (``at_rest_halved``), on the answer's
  grid otherwise unchanged, and the three durations extrapolated: on yamamoto_2r, whose joints
  have no jerk limit, a named grid of 100 intervals answered 2.7e-3 above the torque-limited
  optimum (which the jerk-limited one equals there) and stated 3.9e-5.

Each solve here starts from the answer (few LPs); its cost is measured by
``benchmarks/jerk_gap.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.timing.base import Boundary
from toptraj.planners.timing.jerk.accuracy import at_rest_halved, extrapolated_errors, refined, relative_gap
from toptraj.planners.timing.jerk.scaling import JerkTimeScaling

#: The length in s of the constant-jerk phase at an end at rest: (constraints, end) -> length.
PhaseLength = Callable[[PathConstraints, int], float]
#: Solves the LPs on a grid, started from a solution on another: (constraints, start) -> solution.
GridSolve = Callable[[PathConstraints, JerkTimeScaling], JerkTimeScaling]


def stated_gap(
    solve: GridSolve, affordable: bool, constraints: PathConstraints, boundary: Boundary, answer: JerkTimeScaling,
    chain: Sequence[float], unfilled: tuple[int, ...], how: str,
) -> tuple[float | None, str]:
    """The relative gap of ``answer`` (the solution on ``constraints``) and how it was found
    (``None`` and why, where a solve for the estimate failed).

    Args:
        solve: The method's LPs on a grid (``GridSolve``).
        affordable: Whether a grid twice as fine fits the budget (else the difference from the
            second grid is stated, first order assumed, as ``how`` says).
        chain: Durations (s) on the nested grids solved so far, coarsest first, the answer's last
            (at least two: the second grid's and the answer's; more where the method refined).
        unfilled: The ends at rest (0, -1) that no constant-jerk phase fills.
        how: How the difference from the second grid was found.
    """
    duration = answer.duration
    if len(chain) >= 3:
        error, basis = abs(chain[-2] - chain[-1]), how
    elif affordable:
        try:
            finer = solve(refined(constraints, boundary), answer)
        except (InfeasiblePath, TimingFailed) as failure:
            return relative_gap(chain[-2], chain[-1]), f"{how} (first order assumed: the finer grid's solve failed, {failure.detail})"
        error = extrapolated_errors((chain[-2], chain[-1], finer.duration))[1]
        basis = f"{how} and from a grid twice as fine ({len(finer.s) - 1} intervals), extrapolated with their order"
    else:
        return relative_gap(chain[-2], chain[-1]), f"{how} (first order assumed: no time for a finer grid)"
    if unfilled and affordable:
        halved = at_rest_halved(constraints, unfilled)
        try:
            once = solve(halved, answer)
            twice = solve(at_rest_halved(halved, unfilled), once)
        except (InfeasiblePath, TimingFailed) as failure:
            return None, f"none: the intervals at rest, which no jerk phase fills, could not be halved ({failure.detail})"
        error += extrapolated_errors((duration, once.duration, twice.duration))[0]
        basis += "; with the error of the intervals at rest, which no jerk phase fills, from halving them twice"
    elif unfilled:
        basis += "; without the error of the intervals at rest, which no jerk phase fills (no time to estimate it)"
    return error / max(duration - error, 0.5 * duration), basis


def unfilled_ends(constraints: PathConstraints, boundary: Boundary, phase: PhaseLength) -> tuple[int, ...]:
    """The ends (0, -1) at rest where no jerk limit binds (an infinite ``phase``), or whose
    constant-jerk phase is shorter than half their first interval (the floor of
    ``toptraj.planners.timing.jerk.rest_phase.graded``): elsewhere the first interval holds half the
    phase, and halving it would leave part of the phase to intervals of linear u."""
    s = constraints.s
    ends = []
    for end, sd, first in ((0, boundary.sd_start, s[1] - s[0]), (-1, boundary.sd_end, s[-1] - s[-2])):
        length = phase(constraints, end) if sd == 0.0 else 0.0
        if sd == 0.0 and not (math.isfinite(length) and length >= 0.5 * first):
            ends.append(end)
    return tuple(ends)
