"""How far an answer lies from the converged optimum of its method's problem, and the policy
that holds it within ``GAP_TARGET``.

Every grid method solves a discretization of its problem; its answer's objective (the duration,
or min_cost's cost with a torque weight) differs from the converged one (the limit as the grid
interval goes to zero) by a discretization error. Each answer states an estimate of that
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

The policy (``finer_constraints``, applied by ``toptraj.planners.checks.gate.gated``): for a time-optimal method
on its default grid, an estimate above ``GAP_TARGET`` refines the grid where the phase-plane
method's refinement put its points (the intervals that carry the error), within the method's grid
cap and the time budget, and solves again; the finer answer replaces the first only when it too
holds the limits. An explicit ``timing.grid_points`` keeps its grid. What is still above the target after
that is said in a warning that gives the figure and a followable remedy (``gap_warning``).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.paths.grid import MAX_POINTS, on_points
from toptraj.planners.results import Accuracy
from toptraj.planners.timing.base import GAP_TARGET, Boundary, PathTiming, TimeScaling, TimingMethod
from toptraj.planners.timing.phase_plane.method import GAP_BASIS as PHASE_PLANE_BASIS
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.planners.timing.scaled import solve_well_scaled
from toptraj.robots.notes import Note

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
    if not _affordable(deadline, spent * (intervals + extra.size) / intervals):
        return None
    return constraints.with_points(extra)


def gap_warning(method: TimingMethod, gap: float, intervals: int, dof: int, grid_given: bool) -> Note:
    """The warning of a time-optimal answer whose estimated gap exceeds ``GAP_TARGET``, with
    a remedy the request can follow (the note's ``remedy``): on a grid the request named, a
    number of grid intervals ``wanted`` within what the method serves (first order: the gap
    shrinks as the intervals grow); on the default grid, which ``accurate_solve`` refined as far
    as it could (the cap or the budget stopped it, or the gap is not the grid's), the
    phase-plane method, which refines where the error lies; none for the phase-plane method
    itself, or for jerk_limited beyond its cap (phase_plane would drop the jerk limits)."""
    cap = min(method.max_grid_intervals(dof), MAX_POINTS)
    wanted = math.ceil(1.25 * intervals * gap / GAP_TARGET)
    more_points = intervals < wanted <= cap and (grid_given or method.name == "jerk_limited")
    if more_points:
        remedy = "grid.intervals"
    elif method.name not in ("jerk_limited", "phase_plane"):
        remedy = "method"
    else:
        remedy = None
    return Note(
        f"the duration is within about {100 * gap:.2g} % of the time-optimal one on this grid of {intervals} intervals",
        "gap_above_target", gap=gap, intervals=intervals, wanted=wanted if more_points else None, cap=cap, method=method.name,
        grid_given=grid_given, remedy=remedy, target=GAP_TARGET,
    )


def answer_accuracy(
    timing: PathTiming,
    method: TimingMethod,
    method_name: str,
    intervals: int,
    dof: int,
    grid_given: bool,
    duration_given: bool,
    law_utilization: list[tuple[float, dict[str, np.ndarray]]] | None = None,
) -> tuple[Accuracy, Note | None]:
    """The answer's ``Accuracy`` from its timing, and the warning the policy asks for: a
    time-optimal answer (``method``: the method that timed the path) whose estimated gap still
    exceeds ``GAP_TARGET`` after ``accurate_solve`` on its ``intervals`` grid intervals (a
    ``Note``). Time laws at their shortest (``law_utilization``: each stretch's duration and
    its dense check's peak utilization against the limits it was timed under) are estimated
    from that (``law_gap``), the stretches' gaps weighted by their durations."""
    gap, basis = timing.optimality_gap, timing.gap_basis
    if method.name == "jerk_limited" and isinstance(timing, TimeScaling):
        intervals = len(timing.s) - 1  # the grid it refined to, not the one it started from
    if gap is None and law_utilization and not duration_given:
        gaps = [law_gap(utilization) for _, utilization in law_utilization]
        known = [(duration, g) for (duration, _), g in zip(law_utilization, gaps) if g is not None]
        total = sum(duration for duration, _ in known)
        if len(known) == len(gaps) and total > 0.0:
            gap, basis = sum(duration * g for duration, g in known) / total, LAW_BASIS
    if gap is None and duration_given:
        return Accuracy(None, Note("not estimated: the duration given sets it, which is no optimum", "duration_given")), None
    if gap is None:
        return Accuracy(None, basis or Note(f"not estimated for the method {method_name}", "not_estimated", method=method_name)), None
    if method_name == "collocation" and basis == PHASE_PLANE_BASIS:
        # The re-timing along the collocation's path, not the free path's own optimality.
        basis = f"the re-timing along the collocation's path only (not the path's own optimality): {basis}"
    warning = None
    if time_optimal(method) and not duration_given and gap > GAP_TARGET:
        warning = gap_warning(method, gap, intervals, dof, grid_given)
    return Accuracy(float(gap), basis), warning


#: How a time law's duration scales its limited quantities: velocities (and tool speeds) as
#: 1/T, accelerations and the inertial torques as 1/T^2, jerks as 1/T^3.
_LAW_POWERS = {"velocity": 1.0, "acceleration": 2.0, "torque": 2.0, "jerk": 3.0}
LAW_BASIS = (
    "the time law's peak utilization on the dense check: its shortest duration is the one at which, "
    "sped up uniformly, its most used limit binds (velocities scale as 1/T, accelerations and torques "
    "as 1/T^2, jerks as 1/T^3; gravity's share of a torque does not scale, so a torque-bound figure is approximate)"
)


def law_gap(utilization: dict[str, np.ndarray]) -> float | None:
    """The relative gap of a time law's duration T from its own shortest T_min, from its peak
    utilization u_k (|value| / limit, per kind and joint) on the dense check: a uniform speed-up
    by f scales each kind by f^p (``_LAW_POWERS``; tool speeds p = 1), so
    T_min = T max_k u_k^(1/p_k) and the gap is T / T_min - 1. ``None`` when nothing is limited."""
    scales = [
        float(np.max(np.asarray(peak, dtype=float))) ** (1.0 / _LAW_POWERS.get(kind, 1.0))
        for kind, peak in utilization.items()
        if np.size(peak) and np.isfinite(np.max(peak))
    ]
    largest = max(scales, default=0.0)
    return max(1.0 / largest - 1.0, 0.0) if largest > 0.0 else None
