"""``phase_plane``: time-optimal path timing by numerical integration in the (s, sd) phase plane.

The method of Bobrow, Dubowsky & Gibson, Shin & McKay and Pfeiffer & Johanni as Jeong & Lee
section 3 describe it: along the path the limits bound the path acceleration u = sdd between
alpha(s, x) and beta(s, x) (x = sd^2; Jeong & Lee eq. (3.6) solved for mu-dot), the optimal
profile accelerates at beta as long as it can and decelerates at alpha when it must, and it
touches the maximum velocity curve (MVC) only at switching points: tangent points, points where
the MVC jumps, and singular points where the u-coefficient of a binding row vanishes (zero
inertia).

The integration runs in its reachability form, which makes every switching point fall out of
two sweeps instead of a search:

1. Backward, from the end state, at maximum deceleration alpha, restarted from the MVC wherever
   the backward curve would cross it: the envelope K(s) of every maximum-deceleration curve
   that ends at the end state or leaves the MVC. Below K the end is reachable; above it, not.
2. Forward, from the start state, at maximum acceleration beta, capped by K.

Where the forward curve meets K it switches from acceleration to deceleration; where it leaves K
it starts accelerating from a point of the MVC or of a deceleration curve through one, which is
exactly a switching point of the classical method. At a singular point the admissible u-interval
collapses to one value and the sweeps take it: no chattering, no special case.

Discretization: on the grid s_0 < ... < s_N, u is constant per interval (x linear in s) and every
row holds at both ends of each interval (x_i+1 = x_i + 2 ds u), so the limits hold at every grid
point and, to second order, between them. Each sweep step is a closed-form minimum over the rows
(``toptraj.planners.constraints.admissible_kernels``, ``toptraj.planners.timing.phase_plane.sweep_kernels``): no LP is solved anywhere; one compiled call
per sweep pair builds the rows of every interval, linearizes viscous friction, finds the
admissible intervals and runs both sweeps, without holding the GIL. This constant-u scheme is conservative by a first-order
amount, so the grid is refined where it costs time: the error of each interval is estimated from
the midpoint discretization on the same grid (second-order accurate, but not conservative), from
the time it would save by switching inside the interval (a start from rest, a switch onto or off
the MVC within one interval, which neither discretization sees) and from the chord error along
a curved MVC; the intervals are split into whole pieces, the fewest in all that bring the
estimate under the tolerance (each new piece where it removes the most error), with the
constraint rows evaluated anew at the new points (one batched evaluation per round),
until the estimated duration error is below the tolerance. The same rounds split the intervals
where a limit, held at both ends, bulges past itself between them by more than a small fraction
(``toptraj.planners.timing.phase_plane.refinement_kernels.row_excursions``: the rows and the speed bound at the quarter
points from the cubic through the neighbouring grid points, no dynamics evaluated), so that on a
coarse grid the answer holds its limits between grid points too, not only at them.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.admissible import admissible_set
from toptraj.planners.constraints.admissible_kernels import NOTHING_BEFORE, NOTHING_KEPT, zero_inertia_intervals
from toptraj.planners.constraints.held_load import blocked_even_at_rest, holding_facts, static_load
from toptraj.planners.constraints.path_constraints import LinearRows, PathConstraints
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import AT_REST, Boundary, TimeScaling, TimingMethod
from toptraj.planners.timing.friction import friction_passes
from toptraj.planners.timing.phase_plane.grid import (
    Grid,
    Profile,
    interval_rows,
    interval_times,
    kept_intervals,
    midpoint_stage_rows,
)
from toptraj.planners.timing.phase_plane.refinement_kernels import refinement, row_excursions
from toptraj.planners.timing.phase_plane.split_kernels import split_points
from toptraj.planners.timing.phase_plane.sweep_kernels import sweeps

#: Relative slack when comparing x values computed along different routes.
SLACK = 1e-9
#: Relative slack of a boundary speed above the reachable envelope. A time-optimal motion that
#: starts at a limit (the re-timing of a free path from a moving start) starts on the envelope,
#: which the discretization places a few 1e-7 lower; the first interval then absorbs the
#: difference, a relative change of its acceleration of that order.
BOUNDARY_SLACK = 1e-5


#: A switching point is singular where a row's u-coefficient in its interval is within this
#: fraction of the row's scale of zero (``toptraj.planners.constraints.admissible_kernels.zero_inertia_intervals``).
_ZERO_INERTIA_SWITCH = 1e-6
#: Pieces into which one refinement round may split an interval at most.
_MAX_PIECES = 8
#: Refinement aims at this fraction of the tolerance, so that one round usually suffices.
_AIM = 0.85
#: Weight, in the estimated error, of the estimates that may cancel in its signed sum or
#: estimate nothing (``toptraj.planners.timing.phase_plane.refinement_kernels.refinement``): a guard against their own errors.
_GUARD = 0.15
#: Relative excess of a row over its limit, midway between two grid points, above which the
#: interval is split (``toptraj.planners.timing.phase_plane.refinement_kernels.row_excursions``), well within the dense
#: check's ``toptraj.planners.checks.gate.LIMIT_TOLERANCE``.
_EXCURSION = 3e-4
#: The refined grid has at most 2^max_refinements times the intervals of the given one (what
#: halving every interval in each round would give), or this many, whichever is more.
_MIN_REFINED_INTERVALS = 4096


class PhasePlaneMethod(TimingMethod):
    """Time-optimal timing by phase-plane integration (see the module docstring).

    Args:
        tolerance: Relative duration error at which grid refinement stops. The error is
            estimated from the midpoint discretization on the same grid (second order, so it
            stands for the exact answer), from the time each interval would save by switching
            inside it, and from the chord error along the maximum velocity curve
            (``toptraj.planners.timing.phase_plane.refinement_kernels.refinement``); intervals are split where the estimates lie,
            each into as many pieces as its share asks for, with the constraint rows evaluated
            anew at the new points, until the estimate falls below ``tolerance`` or
            ``max_refinements`` rounds are done.
        max_refinements: Rounds of refinement; 0 keeps the given grid.
        excursion: In each round, intervals are also split where a limit, held at both ends,
            is estimated to be exceeded by more than this fraction midway between them
            (``toptraj.planners.timing.phase_plane.refinement_kernels.row_excursions``); ``None``: the duration alone
            decides where points go, and the limits hold at the grid points only.

    The answer carries the last estimate of its relative duration error as its
    ``optimality_gap`` (``GAP_BASIS``): the one that stopped the refinement, or, when the
    rounds ran out on a split, one more midpoint solve on the final grid.
    """

    name = "phase_plane"
    #: About 1.3 kB per grid interval and joint (``benchmarks/budgets.py``).
    bytes_per_interval_joint = 1_300

    def __init__(self, tolerance: float = 6e-4, max_refinements: int = 3, excursion: float | None = _EXCURSION):
        self.tolerance = tolerance
        self.max_refinements = max_refinements
        self.excursion = excursion

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> TimeScaling:
        x_ends = (boundary.sd_start**2, boundary.sd_end**2)
        most_intervals = max(2**self.max_refinements * (len(constraints.s) - 1), _MIN_REFINED_INTERVALS)
        grid = Grid.of(constraints)
        profile = _solve_on_grid(grid, x_ends, deadline, midpoint=False)
        kept, reference_bounds = NOTHING_KEPT, NOTHING_BEFORE
        # The estimated duration error of ``profile``, and whether it is the estimate on its
        # own grid (else on the coarser grid before the last split, which only removes error).
        error, estimated = None, False
        rounds = self.max_refinements if constraints.can_refine else min(self.max_refinements, 1)
        for _ in range(rounds):
            try:
                reference = _solve_on_grid(grid, x_ends, deadline, midpoint=True, x_ref=profile.x, kept=kept, before=reference_bounds)
            except InfeasiblePath:
                error, estimated = None, True
                break
            room = most_intervals - (len(grid.s) - 1) if constraints.can_refine else 0
            ceiling = np.concatenate((profile.x_high, grid.x_bound[-1:]))
            wanted, priority, error = refinement(
                grid.s, profile.x, reference.x, ceiling, profile.switch_excess, self.tolerance, _AIM, _GUARD, _MAX_PIECES, room
            )
            estimated = True
            if not constraints.can_refine:
                break
            if error <= self.tolerance:
                if self.excursion is None:
                    break
                # The duration is within its tolerance: the limits' excursions between grid
                # points decide a last split.
                wanted = row_excursions(grid.s, *grid.rows, grid.x_bound, grid.binding, grid.smooth, profile.x, self.excursion, _MAX_PIECES)
            extra = split_points(grid.s, wanted, priority, _MAX_PIECES, room)
            if extra.size == 0:
                break
            deadline.check()
            previous = grid
            grid = Grid.of(grid.constraints.with_points(extra))
            # The profile on the coarser grid is a close reference for viscous friction.
            x_ref = np.interp(grid.s, previous.s, profile.x) if grid.friction else None
            kept, reference_bounds = kept_intervals(grid.s, previous.s), reference.bounds
            profile = _solve_on_grid(grid, x_ends, deadline, midpoint=False, x_ref=x_ref, kept=kept, before=profile.bounds)
            estimated = error <= self.tolerance  # within it before the split: still within it
            if error <= self.tolerance:
                break  # split for the limits' excursions alone
        if rounds and not estimated:
            # The rounds ended on a split whose grid was not estimated: one more midpoint solve.
            error = _duration_error(grid, profile, x_ends, deadline, self.tolerance)
        switches = _switch_points(grid.constraints, profile)
        if not rounds:
            gap, basis = None, "not estimated (grid refinement is off)"
        elif error is None:
            gap, basis = None, "not estimated: the midpoint discretization finds no motion on this grid"
        else:
            gap, basis = float(error), GAP_BASIS
        return TimeScaling(grid.s, np.sqrt(profile.x), switches, optimality_gap=gap, gap_basis=basis)


#: How ``PhasePlaneMethod`` estimates its duration error (``TimeScaling.gap_basis``).
GAP_BASIS = (
    "phase_plane's error estimate on its final grid: this (conservative) discretization against the "
    "second-order midpoint one, the time saved by switching inside an interval and the chord error "
    "along the maximum velocity curve"
)


def _duration_error(grid: Grid, profile: Profile, x_ends, deadline, tolerance: float) -> float | None:
    """The relative duration error of ``profile`` on ``grid``, estimated as in the refinement
    (``toptraj.planners.timing.phase_plane.refinement_kernels.refinement``); ``None`` when the midpoint discretization finds
    no motion."""
    try:
        reference = _solve_on_grid(grid, x_ends, deadline, midpoint=True, x_ref=profile.x)
    except InfeasiblePath:
        return None
    ceiling = np.concatenate((profile.x_high, grid.x_bound[-1:]))
    return float(refinement(grid.s, profile.x, reference.x, ceiling, profile.switch_excess, tolerance, _AIM, _GUARD, _MAX_PIECES, 0)[2])


def midpoint_duration(constraints: PathConstraints, boundary: Boundary = AT_REST) -> float:
    """The duration (s) in the midpoint discretization on the constraints' own grid, without
    refinement: second-order accurate, but no bound (the limits may be exceeded between grid
    points). On a fine grid, an estimate of the converged time-optimal duration."""
    states = (boundary.sd_start**2, boundary.sd_end**2)
    grid = Grid.of(constraints)
    first = _solve_on_grid(grid, states, NO_DEADLINE, midpoint=False)
    second = _solve_on_grid(grid, states, NO_DEADLINE, midpoint=True, x_ref=first.x)
    return float(interval_times(grid.s, second.x).sum())


def _solve_on_grid(grid: Grid, boundary: tuple[float, float], deadline, midpoint: bool, x_ref=None, kept=NOTHING_KEPT, before=NOTHING_BEFORE) -> Profile:
    """Integrate on one grid, in the interpolation (conservative) or the midpoint
    discretization. Viscous friction is linearized around ``x_ref`` (default: the passes of
    ``_friction_passes``). ``kept`` and
    ``before``: the intervals this grid keeps whole from a coarser one and that grid's bounds
    in the same discretization (``Profile.bounds``), copied instead of computed again."""
    x_start, x_end = boundary
    if x_ref is None and grid.friction:
        return _friction_passes(grid, x_start, x_end, deadline, midpoint, kept, before)
    x_ref = grid.x_bound if x_ref is None else x_ref
    return _integrate(grid, np.ascontiguousarray(x_ref, dtype=np.float64), x_start, x_end, deadline, midpoint, kept, before)


def _friction_passes(grid: Grid, x_start: float, x_end: float, deadline, midpoint: bool, kept, before) -> Profile:
    """The profile with viscous friction, its tangent taken around the frictionless maximum
    velocity curve (``Grid.friction_reference``), then around its answer
    (``toptraj.planners.timing.friction``: lowered where it finds no motion)."""

    def solve(x_ref: np.ndarray) -> Profile:
        return _integrate(grid, np.ascontiguousarray(x_ref, dtype=np.float64), x_start, x_end, deadline, midpoint, kept, before)

    def duration(profile: Profile) -> float:
        return float(interval_times(grid.s, profile.x).sum())

    return friction_passes(solve, grid.friction_reference(), lambda profile: profile.x, duration, passes=1)


def _integrate(grid: Grid, x_ref, x_start, x_end, deadline, midpoint, kept=NOTHING_KEPT, before=NOTHING_BEFORE) -> Profile:
    """One sweep pair (``toptraj.planners.timing.phase_plane.sweep_kernels.sweeps``) on ``grid``; a failure is explained from the
    rows linearized around ``x_ref``."""
    x_bound, constraints = grid.x_bound, grid.constraints
    if x_end > x_bound[-1] * (1 + SLACK) + SLACK:
        raise InfeasiblePath(
            f"the end path speed {np.sqrt(x_end):.6g} 1/s is above the maximum velocity curve "
            f"({np.sqrt(x_bound[-1]):.6g} 1/s) at s = 1",
            s=1.0,
        )
    deadline.check()
    x, capped, envelope, floor, failed, x_high, switch_excess, bounds = sweeps(
        grid.s, *grid.rows, x_bound, x_ref, grid.friction, float(x_start), float(x_end), midpoint, SLACK, kept, before
    )
    if failed >= 0:
        discretize = midpoint_stage_rows if midpoint else interval_rows
        stage = discretize(constraints.s, constraints.linearized(x_ref), constraints.linearized(x_ref, "left"))
        raise _stuck(constraints, admissible_set(stage, x_bound[:-1]), stage, int(failed))
    if x_start < floor[0] * (1 - 1e-7) - 1e-12:
        held, joint, limit = static_load(constraints, 0)
        raise InfeasiblePath(
            f"the motion cannot start at path speed {np.sqrt(x_start):.6g} 1/s at s = 0: every "
            f"motion that can follow the path needs at least {np.sqrt(floor[0]):.6g} 1/s there",
            s=0.0,
            joint=joint,
            limit=limit,
            held=held,
            **holding_facts(constraints),
        )
    if x_start > envelope[0] * (1 + BOUNDARY_SLACK) + 1e-12:
        raise InfeasiblePath(
            f"the start path speed {np.sqrt(x_start):.6g} 1/s is above what the limits allow at s = 0 "
            f"({np.sqrt(max(envelope[0], 0.0)):.6g} 1/s: the maximum velocity curve or the fastest "
            "speed from which the rest of the path can still be followed)",
            s=0.0,
        )
    x[0], x[-1] = x_start, x_end
    return Profile(np.maximum(x, 0.0), capped, envelope, x_high, switch_excess, bounds)


def _switch_points(constraints: PathConstraints, profile: Profile) -> tuple[tuple[float, str], ...]:
    """Where the profile changes between accelerating (at beta) and following the envelope."""
    capped, envelope, x_high = profile.capped, profile.envelope, profile.x_high
    changes = (np.flatnonzero(capped[1:] != capped[:-1]) + 1).tolist()
    if not changes:
        return ()
    s, last = constraints.s, len(x_high) - 1
    # Leaving the envelope: the touch point on (or the deceleration curve from) the MVC.
    on_mvc = [bool(envelope[i] >= x_high[min(i, last)] * (1 - 1e-6)) for i in changes]
    # Only a departure from the MVC can be singular: its intervals' rows, in one batch.
    departs = [min(i, last) for i, on in zip(changes, on_mvc) if on and not capped[i]]
    singular = {}
    if departs:
        found = zero_inertia_intervals(
            s, constraints.a, constraints.b, constraints.a_left, constraints.b_left, np.array(departs, dtype=np.int64), _ZERO_INERTIA_SWITCH
        )
        singular = dict(zip(departs, found.tolist()))
    points = []
    for i, on in zip(changes, on_mvc):
        if capped[i]:
            kind = "deceleration"
        elif not on:
            kind = "acceleration"
        elif singular[min(i, last)]:
            kind = "singular"
        elif 1 <= i < last and abs(x_high[i + 1] - x_high[i - 1]) > 0.25 * max(x_high[i], 1e-12):
            kind = "discontinuity"
        else:
            kind = "tangent"
        points.append((float(s[i]), kind))
    return tuple(points)


def _stuck(constraints: PathConstraints, admissible, stage: LinearRows, i: int) -> InfeasiblePath:
    """No admissible state at interval ``i`` lets the motion reach the end: say where and why."""
    s = constraints.s
    if admissible.x_max[i] < admissible.x_min[i]:
        empty = np.flatnonzero(admissible.x_max < admissible.x_min)
        return blocked_even_at_rest(constraints, admissible.blocking_rows, empty, i, f"between s = {s[i]:.4f} and s = {s[i + 1]:.4f}")
    held, joint, limit = static_load(constraints, i + 1)
    return InfeasiblePath(
        f"no motion can follow the path from s = {s[i]:.4f} to its end: the limits cannot bring "
        f"the motion to the required speed by s = {s[i + 1]:.4f}",
        s=float(s[i]),
        joint=joint,
        limit=limit,
        held=held,
        **holding_facts(constraints),
    )
