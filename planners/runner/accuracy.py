"""The accuracy an answer states (``Accuracy``): the estimated relative gap of its timing to the
converged optimum of its method's problem, as the limit gate estimated it
(``toptraj.planners.checks.accuracy``), or a time law's from its peak utilization, or a
motion generator's own; and the warning, with a followable remedy, where it stays above
``GAP_TARGET``.
"""

from __future__ import annotations

import math

import numpy as np

from toptraj.planners.checks.accuracy import time_optimal
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.planners.results import Accuracy
from toptraj.planners.timing.base import GAP_TARGET, PathTiming, TimeScaling, TimingMethod
from toptraj.planners.timing.phase_plane.method import GAP_BASIS as PHASE_PLANE_BASIS
from toptraj.robots.notes import Note


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
