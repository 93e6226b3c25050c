"""How far a timing lies from the converged optimum of its method's problem, estimated apart from
the solve, and the policy that holds it within ``GAP_TARGET`` (applied by the limit gate,
``toptraj.planners.checks.gate.gated``; the answer states the result,
``toptraj.planners.runner.accuracy``).

Every grid method solves a discretization of its problem; its answer's objective (the duration,
or min_cost's cost with a torque weight) differs from the converged one (the limit as the grid
interval goes to zero) by a discretization error. Each timing carries an estimate of that
relative error, found independently of the solve:

* ``phase_plane``: its own refinement estimate (``toptraj.planners.timing.phase_plane.method.GAP_BASIS``): the
  conservative discretization against the second-order midpoint one on the same grid, plus the
  switches and chords neither sees. No extra solve.
* ``toppra``, ``min_cost`` with beta = 0: the phase-plane method on the same constraints, a
  second, independent algorithm refined to its own estimate g_ref: with its duration T_ref, the
  converged optimum is T* ~ T_ref / (1 + g_ref), and the answer's gap |T / T* - 1|.
* ``min_cost`` with beta > 0: the cost on every other grid point (half the intervals, the knots
  kept). The scheme is first order in the interval length h, J(h) = J* + C h, so the answer's
  error J(h) - J* is about J(2h) - J(h) (the Richardson difference).

The policy (``finer_constraints``): for a time-optimal method on its default grid, an estimate
above ``GAP_TARGET`` refines the grid where the phase-plane method's refinement put its points
(the intervals that carry the error), within the method's grid cap and the time budget, and
solves again; the finer answer replaces the first only when it too holds the limits. An
explicit grid keeps its grid.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.paths.grid import MAX_POINTS, on_points
from toptraj.planners.timing.base import GAP_TARGET, Boundary, PathTiming, TimeScaling, TimingMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.planners.timing.scaled import solve_well_scaled

#: Refinements of the grid for accuracy, each followed by a solve.
REFINE_ROUNDS = 2
#: A refinement or an estimate is started only when the budget left holds this many times its
#: expected time (the last solve's time, scaled by the grid's growth).
BUDGET_FACTOR = 3.0
#: The reference of ``toppra`` and ``min_cost``: the phase-plane method refined to this
#: relative duration error (a quarter of the target: the reference's own error is added).
REFERENCE_TOLERANCE = 2.5e-4

AGAINST_PHASE_PLANE = (
    "the phase-plane method on the same limits, refined to its own error estimate g: with its "
    "duration T_ref the optimum is about T_ref / (1 + g)"
)
HALF_GRID = (
    "the cost on every other grid point (half the intervals): the first-order Richardson "
    "difference J(2h) - J(h)"
)


def time_optimal(method: TimingMethod) -> bool:
    """Whether ``method`` finds the shortest duration along the path (its objective is the
    duration): phase_plane, toppra, jerk_limited and min_cost without a torque weight."""
    return method.name in ("phase_plane", "toppra", "jerk_limited") or (
        method.name == "min_cost" and getattr(method, "torque_weight", 0.0) == 0.0
    )


def _affordable(deadline: Deadline, seconds: float) -> bool:
    remaining = deadline.remaining()
    return remaining is None or remaining > BUDGET_FACTOR * seconds


def _with_gap(result: TimeScaling, gap: float | None, basis: str) -> TimeScaling:
    return dataclasses.replace(result, optimality_gap=None if gap is None else float(gap), gap_basis=basis)


def _against_phase_plane(
    constraints: PathConstraints, boundary: Boundary, result: TimeScaling, deadline: Deadline
) -> tuple[TimeScaling, np.ndarray | None]:
    """``result`` with its gap against the phase-plane method on ``constraints``, and the grid
    the phase-plane method refined to (``None`` without an estimate)."""
    try:
        reference = PhasePlaneMethod(tolerance=REFERENCE_TOLERANCE).solve(constraints, boundary, None, deadline)
    except (InfeasiblePath, TimingFailed):
        return _with_gap(result, None, "not estimated: the phase-plane method finds no motion on these limits"), None
    if reference.optimality_gap is None:
        return _with_gap(result, None, f"not estimated: {reference.gap_basis}"), None
    optimum = reference.duration / (1.0 + reference.optimality_gap)
    gap = abs(result.duration / optimum - 1.0)
    return _with_gap(result, gap, AGAINST_PHASE_PLANE), reference.s


def coarser(constraints: PathConstraints) -> PathConstraints:
    """``constraints`` on every other grid point, the ends and the path's knots kept."""
    n = len(constraints.s)
    keep = np.zeros(n, dtype=bool)
    keep[::2] = True
    keep[-1] = True
    if constraints.knots is not None:
        keep |= on_points(constraints.s, np.asarray(constraints.knots, dtype=float))
    index = np.flatnonzero(keep)

    def take(array):
        return None if array is None else np.asarray(array).take(index, axis=0)

    def take_all(arrays):
        return None if arrays is None else tuple(take(a) for a in arrays)

    jerk = None if constraints.jerk is None else (*take_all(constraints.jerk[:3]), constraints.jerk[3])
    return dataclasses.replace(
        constraints,
        s=take(constraints.s), sd_max=take(constraints.sd_max),
        a=take(constraints.a), b=take(constraints.b), c=take(constraints.c), d=take(constraints.d),
        a_left=take(constraints.a_left), b_left=take(constraints.b_left),
        c_left=take(constraints.c_left), d_left=take(constraints.d_left),
        lower=take(constraints.lower), upper=take(constraints.upper),
        jerk=jerk, jerk_left=take_all(constraints.jerk_left),
        velocity_joint=take(constraints.velocity_joint), tool_bound=take(constraints.tool_bound), q=take(constraints.q),
    )  # fmt: skip


def _cost_on_half_grid(method, constraints, boundary, result, deadline, spent: float) -> TimeScaling:
    """``result`` (a cost) with its gap from the same method on half the intervals."""
    cost = getattr(result, "cost", None)
    if cost is None or not cost > 0.0:
        return _with_gap(result, None, "not estimated: the method reports no cost")
    if len(constraints.s) < 5:
        return _with_gap(result, None, "not estimated: the grid is too coarse to halve")
    if not _affordable(deadline, spent):
        return _with_gap(result, None, "not estimated: the time budget left is too short for a second solve")
    try:
        half = solve_well_scaled(method, coarser(constraints), boundary, None, deadline)
    except (InfeasiblePath, TimingFailed):
        return _with_gap(result, None, "not estimated: the method finds no timing on half the grid")
    return _with_gap(result, abs(getattr(half, "cost", math.nan) - cost) / cost, HALF_GRID)


def estimated(
    method: TimingMethod,
    constraints: PathConstraints,
    boundary: Boundary,
    result: PathTiming,
    deadline: Deadline,
    spent: float = 0.0,
) -> tuple[PathTiming, np.ndarray | None]:
    """``result`` with its ``optimality_gap`` (module docstring), and a finer grid that holds
    the error where it lies (the phase-plane method's refined grid) when one is known. A timing
    that estimates itself, or that is no grid timing, is returned as it is."""
    if not isinstance(result, TimeScaling):
        return result, None
    if method.name == "phase_plane":
        return result, result.s
    if result.optimality_gap is not None:
        return result, None
    if time_optimal(method) and method.name != "jerk_limited":  # the phase plane knows no jerk limit
        return _against_phase_plane(constraints, boundary, result, deadline)
    if method.name == "min_cost":
        return _cost_on_half_grid(method, constraints, boundary, result, deadline, spent), None
    return result, None


def finer_constraints(
    method: TimingMethod,
    constraints: PathConstraints,
    result: PathTiming,
    finer: np.ndarray | None,
    spent: float,
    deadline: Deadline,
    keep_grid: bool,
) -> PathConstraints | None:
    """The policy: the constraints on the grid ``finer`` (where the phase-plane method's
    refinement put its points, ``estimated``) when ``result`` is a time-optimal timing whose
    estimated gap exceeds ``GAP_TARGET``, the grid is not to be kept (``keep_grid``: the
    request named it, or asked for a duration), the finer grid is within the method's cap and
    the budget left holds a solve on it (the last one took ``spent`` seconds); else ``None``."""
    gap = result.optimality_gap
    if keep_grid or not time_optimal(method) or gap is None or gap <= GAP_TARGET or finer is None or not constraints.can_refine:
        return None
    extra = finer[~on_points(finer, constraints.s)]
    intervals = len(constraints.s) - 1
    cap = min(method.max_grid_intervals(len(constraints.joint_names)), MAX_POINTS)
    if extra.size == 0 or intervals + extra.size > cap:
        return None
    # What does not grow with the grid (a worker process started: ``CostTimeScaling.fixed_seconds``)
    # is paid again as it is; the rest grows with the intervals plus the method's set-up, counted
    # in intervals (``TimingMethod.setup_intervals``).
    fixed = min(float(getattr(result, "fixed_seconds", 0.0)), spent)
    setup = method.setup_intervals
    if not _affordable(deadline, fixed + (spent - fixed) * (intervals + extra.size + setup) / (intervals + setup)):
        return None
    return constraints.with_points(extra)
