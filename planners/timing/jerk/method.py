"""``jerk_limited``: time-optimal timing along the given path under velocity, acceleration,
torque **and jerk** limits.

Along q(s) the joint jerk is

    qddd = q' sddd + 3 q'' sd sdd + q''' sd^3,

third order in the path parameter, and with the usual variables of the phase plane, x = sd^2
and u = sdd, it is nonconvex: with du/ds = sddd / sd it reads sd (q' du/ds + 3 q'' u + q''' x),
so that a limit |qddd_k| <= J_k is

    |q'_k du/ds + 3 q''_k u + q'''_k x| <= J_k / sqrt(x).                            (1)

The literature read before choosing (DESIGN.md asks for it):

* TOPP3 (Pham & Pham, "On the structure of the time-optimal path parameterization problem with
  third-order constraints", arXiv 1609.05307, ICRA 2017) integrates profiles in the
  (s, sd, sdd) space, bang-bang in sddd, and shows the two difficulties of that route: optimal
  profiles in 3-D no longer meet, and singularities stop the integration. No robust
  implementation of it exists.
* Consolini, Locatelli et al., "A sequential approach for speed planning under jerk
  constraints" (arXiv 2105.15095): a feasible-direction line search on a linearization of the
  problem in x, with a structure-exploiting solver for the linearized problem; written for a
  vehicle with scalar limits along its path.
* Lee, Bylard, Sun & Sentis, "On the performance of jerk-constrained time-optimal trajectory
  planning for industrial manipulators" (arXiv 2404.07889, 2024): the right-hand side of (1),
  J / sqrt(x), is convex in x, so its tangent at any x_ref > 0 lies below it; replacing it by
  that tangent gives a **conservative linear restriction** of (1). Every other limit is already
  linear in (x, u), so each restricted problem is a linear program whose every solution is
  feasible for the true limits, and the sequence of LPs, each restricted around the previous
  solution, converges.

This module implements the last: it holds every limit for manipulators with torque rows as they
are (Lee et al. use joint limits; torque rows are linear in (x, u) too), every iterate is
feasible, and each LP is sparse and solved by HiGHS's dual simplex, warm-started from the
previous LP's basis.

The discretization and the linear program of each restriction are
``toptraj.planners.timing.jerk.program``'s. Each LP step is followed by a line search on the true
duration: along the segment from the current (feasible) solution to the LP's, every point lies
in the current restriction, so the duration decreases monotonically. The first restriction is
taken around the jerk-free time-optimal profile (``phase_plane``).

The grid solution follows a phase of constant jerk only approximately (within about 0.2 % of
the duration on the default grid). Where every limit is the same along the whole path (a
straight joint line under velocity, acceleration and jerk limits) and the solution has at most
nine phases, ``toptraj.planners.timing.jerk.polish`` refines it in time, as segments of constant jerk
with free switching times: the exact optimum there (Berscheid & Kroeger's profile, the same as
ruckig's along the line). Where, moreover, the motion goes from rest to rest and every row
reduces to a symmetric bound on sd, sdd or sddd alone, the optimum is the double-S profile in
closed form (``toptraj.planners.timing.jerk.closed_form``), returned without solving anything: the
polish is a local method started from the grid solution's phases, and misses the optimum
(keeping the grid solution, up to 2 % above it) where those phases differ from the profile's.

Every answer carries an estimate of its distance from the optimum (``optimality_gap``): zero
for the closed form, else the difference from the solution on a second grid of half as many
points (``toptraj.planners.timing.jerk.accuracy``), which is solved first and starts the LPs of the
answer's grid; a grid of fewer than ``ASYMPTOTIC_INTERVALS`` (where that difference is not
yet first order), or one above ``GAP_TARGET``, is doubled (every interval halved but those at
rest), at most ``max_refinements`` times, while the grid budget and the time left allow, the
gap then the difference between the last two grids. Where the grid was not doubled, the answer's
grid halved is solved for the estimate only; intervals at an end at rest that no constant-jerk
phase fills are halved twice for it (``toptraj.planners.timing.jerk.stated_gap``).

Each LP is solved over a working set of its rows (``toptraj.planners.timing.jerk.working_set``): of
some 50 rows per interval only about two per point are active at the optimum. On fine grids the
second grid is itself started from the grid coarser still, down to ``SEED_INTERVALS`` (a
multigrid start): each level's LPs begin near their optimum, over the rows that bind there, and
only the coarsest level starts from the jerk-free optimum.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InfeasiblePath, NotServed, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import AT_REST, GAP_TARGET, Boundary, TimingMethod
from toptraj.planners.timing.jerk.accuracy import coarser, refined, relative_gap
from toptraj.planners.timing.jerk.closed_form import closed_form_timing
from toptraj.planners.timing.jerk.polish import polish
from toptraj.planners.timing.jerk.program import RestrictedProgram
from toptraj.planners.timing.jerk.rest_phase import graded, opened, start_phase
from toptraj.planners.timing.jerk.scaling import JerkTimeScaling
from toptraj.planners.timing.jerk.segments import JerkSegmentsTiming
from toptraj.planners.timing.jerk.stated_gap import stated_gap, unfilled_ends
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

#: Relative gain below which the LPs on every grid stop: a hundredth of the gap the refinement
#: aims at. A sequence stopped early ends above its grid's fixed point (each LP step shortens
#: the motion), which overstates the gap it estimates on the coarser grid of a pair; the
#: answer's own grid stops there too.
WARM_TOLERANCE = 1e-2 * GAP_TARGET
#: Time of the LPs on a grid twice as fine as the last, as a multiple of the last's, with room:
#: the first LP starts from no basis, its simplex iterations and their cost each about doubling
#: (ur5, 2,000 to 4,000 intervals: 9 to 12 times the last grid's sequence, itself started from
#: the grids below it), and a refinement begun but not finished costs the whole answer.
REFINEMENT_COST = 20.0
#: Memory per grid interval and joint: 37 MB of peak RSS growth for 2,000 intervals on ur5 (4
#: waypoints), its refinements included (about 3.3 kB), rounded up.
JERK_BYTES = 3_500
#: Most intervals a doubling of the grid may reach: each LP's time grows with its grid.
MAX_REFINED_INTERVALS = 12_000
#: Grids of fewer intervals are doubled whatever their estimate: below it the difference
#: between the second grid and the answer's is not yet first order (ur5 example, the intervals
#: at rest kept: 6.5e-4 from 102 to 200 intervals, then 8.4e-4, 3.4e-4, 1.7e-4 and 7.8e-5 over
#: each further halving), and understates the error (1.4e-3 on 200 intervals); one halving
#: further, the difference from the grid before bounds the answer's (8.0e-4 against 6.4e-4).
ASYMPTOTIC_INTERVALS = 300
#: Fewest intervals of a grid that starts the LPs of a finer one (``JerkLimitedMethod._seed``):
#: the cold start, from the jerk-free optimum, is paid on a grid of 30 to 60 intervals (ur5
#: example: 54 intervals, then 102 started from them, in about 18 ms of CPU against 20 ms for
#: 102 intervals started cold; the same solution on 102 intervals).
SEED_INTERVALS = 30


class JerkLimitedMethod(TimingMethod):
    """Time-optimal timing with jerk limits by sequential linear programming over conservative
    convex restrictions (Lee et al. 2024; see the module docstring).

    Args:
        tolerance: Relative decrease of the duration below which the iteration stops.
        max_iterations: Most LPs solved.
        polish: Whether to refine the grid solution in time where the limits do not change.
        max_refinements: Most doublings of the grid while the estimated gap of the answer
            (``toptraj.planners.timing.jerk.accuracy``) exceeds ``GAP_TARGET``.
    """

    name = "jerk_limited"
    kinds = frozenset({"velocity", "acceleration", "torque", "jerk"})
    required_kinds = frozenset({"jerk"})
    continuous_acceleration = True
    #: Each LP holds some 2 (N + 1) columns and 40 rows per grid interval on a 6-joint arm:
    #: 2,000 intervals solve in about a second per LP.
    bytes_per_interval_joint = JERK_BYTES

    def __init__(self, tolerance: float = 1e-7, max_iterations: int = 60, polish: bool = True, max_refinements: int = 2):
        self.tolerance = tolerance
        self.max_iterations = max_iterations
        self.polish = polish
        self.max_refinements = max_refinements

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> JerkTimeScaling | JerkSegmentsTiming:
        if constraints.jerk is None:
            raise NotServed("constraints", None, self.name, rule="jerk_limited_needs_jerk")
        if boundary.sdd_start or boundary.sdd_end:
            raise NotServed("boundary", None, self.name, rule="jerk_limited_from_zero_acceleration")
        if boundary.sd_start == 0.0 and boundary.sd_end == 0.0 and _uniform(constraints):
            exact = closed_form_timing(constraints)
            if exact is not None:
                return exact
        if constraints.can_refine:
            constraints = opened(constraints, boundary)
        original = constraints.s
        constraints = graded(constraints, boundary)
        # The second grid first: its solution starts the LPs on the answer's grid, which then
        # need few iterations over few rows (``toptraj.planners.timing.jerk.working_set``).
        coarse, gap, how = self._second_grid(constraints, original, boundary, deadline)
        started = time.perf_counter()
        best = self._grid_solution(constraints, boundary, deadline, start=coarse, tolerance=WARM_TOLERANCE)
        elapsed = time.perf_counter() - started
        chain = [best.duration]
        if coarse is not None:
            gap = relative_gap(coarse.duration, best.duration)
            chain.insert(0, coarse.duration)
        for done in range(self.max_refinements):
            if gap is None or not self._affordable(constraints, elapsed, deadline):
                break
            if len(constraints.s) - 1 >= ASYMPTOTIC_INTERVALS and gap <= GAP_TARGET:
                break
            # The error about halves with each doubling (first order; the LPs cost ten times or more
            # as much): where the doublings left would not bring it to the target, the answer
            # states its gap instead.
            if gap / 2 ** (self.max_refinements - done) > GAP_TARGET:
                break
            finer = refined(constraints, boundary)
            started = time.perf_counter()
            finer_best = self._grid_solution(finer, boundary, deadline, start=best, tolerance=WARM_TOLERANCE)
            elapsed = time.perf_counter() - started
            gap = relative_gap(best.duration, finer_best.duration)
            how = f"second grid: the difference from the solution on a grid of half as many points ({len(constraints.s) - 1} intervals)"
            constraints, best = finer, finer_best
            chain.append(best.duration)
        if gap is not None:
            gap, how = self._stated_gap(constraints, boundary, best, chain, how, elapsed, deadline)
        if gap is not None and not np.isfinite(gap):  # a grid solved for the estimate stops mid-path
            gap, how = None, UNESTIMATED
        return self._polished(constraints, boundary, dataclasses.replace(best, optimality_gap=gap, gap_basis=how), deadline)

    def _polished(self, constraints: PathConstraints, boundary: Boundary, best: JerkTimeScaling, deadline: Deadline):
        """``best`` refined in time (``toptraj.planners.timing.jerk.polish``) where every limit is
        the same along the path and the polish finds it shorter, with ``best``'s estimate."""
        if self.polish and _uniform(constraints):
            polished = polish(constraints, best, boundary.sd_start, boundary.sd_end, deadline)
            if polished is not None:
                # Shorter than the grid solution and feasible: no farther from the optimum.
                basis = best.gap_basis if best.optimality_gap is None else (
                    f"bounded by the grid solution's estimate, which it improves on ({best.gap_basis})"
                )
                return dataclasses.replace(polished, optimality_gap=best.optimality_gap, gap_basis=basis)
        return best

    def _grid_solution(
        self, constraints: PathConstraints, boundary: Boundary, deadline: Deadline, start: JerkTimeScaling | None = None,
        tolerance: float | None = None,
    ) -> JerkTimeScaling:
        """The sequence of restricted LPs on the grid of ``constraints`` (module docstring), the
        first restriction taken around the jerk-free optimum, or around ``start`` (the solution
        on a coarser grid, which saves most of the LPs), stopped at a relative gain below
        ``tolerance`` (the method's own by default)."""
        tolerance = self.tolerance if tolerance is None else max(tolerance, self.tolerance)
        if start is None:
            reference = PhasePlaneMethod(max_refinements=0).solve(constraints, boundary, None, deadline)
        x_ref = np.maximum((reference if start is None else start).speed_at(constraints.s) ** 2, 0.0)
        problem = RestrictedProgram(constraints, boundary, x_ref, deadline)
        # The first restriction is taken around the jerk-free optimum, which is no feasible
        # point itself; its LP solution is, and every later step starts from a feasible point.
        # Its rows start from those near a bound at x_ref, u from dx/ds = 2 u or, on a finer
        # grid, the coarser solution's (linear between its points; fewer rows to add after).
        u_ref = 0.5 * np.gradient(x_ref, constraints.s) if start is None else np.interp(constraints.s, start.s, start.u)
        x, u = problem.solve_restricted(x_ref, seed=(x_ref, u_ref))
        best = problem.timing(x, u)
        for _ in range(self.max_iterations):
            deadline.check()
            x_lp, u_lp = problem.solve_restricted(x)
            # Line search on the true duration along the segment to the LP's solution, every
            # point of which lies in the (convex) restriction around the current solution.
            steps = 0.5 ** np.arange(8)[:, None]
            x_steps, u_steps = x + steps * (x_lp - x), u + steps * (u_lp - u)
            chosen = int(np.argmin(problem.durations(x_steps, u_steps)))
            x_step, u_step = x_steps[chosen], u_steps[chosen]
            candidate = problem.timing(x_step, u_step)
            gain = best.duration - candidate.duration
            if gain <= 0.0:
                break
            x, u, best = x_step, u_step, candidate
            if gain <= tolerance * best.duration:
                break
        return best

    def _stated_gap(self, constraints, boundary, best, chain, how, elapsed, deadline) -> tuple[float | None, str]:
        """The gap of ``best`` from its grid's, a finer grid's and the intervals at rest's
        errors (``toptraj.planners.timing.jerk.stated_gap``), each solve started from ``best``."""
        unfilled = unfilled_ends(constraints, boundary, start_phase)

        def solve(grid, start):
            return self._grid_solution(grid, boundary, deadline, start=start, tolerance=WARM_TOLERANCE)

        affordable = self._affordable(constraints, elapsed, deadline)
        return stated_gap(solve, affordable, constraints, boundary, best, chain, unfilled, how)

    def _second_grid(self, constraints, original, boundary, deadline) -> tuple[JerkTimeScaling | None, float | None, str]:
        """The solution on every other grid point (``toptraj.planners.timing.jerk.accuracy``), which
        estimates the gap of the answer's grid, and how: (``None``, ``None``, why) when there is
        none."""
        coarse = coarser(constraints, original)
        if coarse is None:
            return None, None, "none: the grid is too coarse for a second one"
        try:
            coarse_best = self._grid_solution(
                coarse, boundary, deadline, start=self._seed(coarse, original, boundary, deadline), tolerance=WARM_TOLERANCE,
            )
        except (InfeasiblePath, TimingFailed) as error:
            return None, None, f"none: the second grid's solve failed ({error.detail})"
        return (
            coarse_best, None,
            f"second grid: the difference from the solution on a grid of half as many points ({len(coarse.s) - 1} intervals)",
        )

    def _seed(self, constraints, original, boundary, deadline) -> JerkTimeScaling | None:
        """Where the LPs on ``constraints`` start: the solution on every other point of their
        grid, itself started from the grid coarser still, down to ``SEED_INTERVALS``; ``None``
        (the jerk-free optimum) below. Each level's LPs then begin near their optimum and over
        the rows that bind there, the cold start paid on a small grid only; the levels below
        the second grid stop at a gain of ``WARM_TOLERANCE``, being starts only."""
        coarse = coarser(constraints, original) if len(constraints.s) - 1 > 2 * SEED_INTERVALS else None
        if coarse is None:
            return None
        try:
            return self._grid_solution(
                coarse, boundary, deadline, start=self._seed(coarse, original, boundary, deadline), tolerance=WARM_TOLERANCE,
            )
        except (InfeasiblePath, TimingFailed):
            return None

    def _affordable(self, constraints: PathConstraints, elapsed: float, deadline: Deadline) -> bool:
        """Whether a grid twice as fine fits the grid budget and (at ``REFINEMENT_COST`` times the
        last solve's time) the time left, on constraints that can be evaluated at new points."""
        if not constraints.can_refine or 2 * (len(constraints.s) - 1) > MAX_REFINED_INTERVALS:
            return False
        remaining = deadline.remaining()
        return remaining is None or remaining > REFINEMENT_COST * elapsed + 1.0


#: Why an answer states no gap where a grid solved for the estimate stopped the motion (x = 0
#: at an inner point: an infinite duration; seen on splines through nearly repeated waypoints).
UNESTIMATED = (
    "none: the solution on a grid solved for the estimate stops the motion inside the path (its duration is "
    "infinite); a finer grid, or dropping waypoints that nearly repeat, gives an estimate"
)


def _uniform(constraints: PathConstraints, tolerance: float = 1e-9) -> bool:
    """Whether every limit is the same along the whole path (a straight joint line under
    velocity, acceleration and jerk limits): the polish's segments of constant path jerk are the
    exact optimum there, and seldom beat the grid solution elsewhere (so it is not tried)."""
    assert constraints.jerk is not None  # jerk_limited always builds the jerk rows
    dq, ddq, dddq, _ = constraints.jerk
    # Spreads are measured against the larger of each array's own magnitude and the path's
    # (|q'|): d2q/ds2 of a straight line is rounding noise of that size, not a change.
    reference = float(np.abs(dq).max(initial=0.0))
    arrays = [constraints.sd_max, dq, ddq, dddq, constraints.a, constraints.b, constraints.c, constraints.d,
              constraints.lower, constraints.upper]
    for values in arrays:
        values = np.asarray(values, dtype=float)
        if values.size == 0:
            continue
        finite = np.isfinite(values)
        if not np.array_equal(finite, np.broadcast_to(finite[:1], finite.shape)):
            return False
        spread = np.ptp(np.where(finite, values, 0.0), axis=0)
        if np.any(spread > tolerance * max(float(np.abs(values[finite]).max(initial=0.0)), reference, 1e-300)):
            return False
    return True
