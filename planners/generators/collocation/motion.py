"""The collocation's answer (``toptraj.planners.generators.collocation.collocation``, Jeong &
Lee section 4): the motion at its K + 1 instants with its torques, its cost and how the solver
got there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from toptraj.planners.generators.via_points import ConstantSpeedTiming, ViaPath


@dataclass(frozen=True)
class CollocationResult:
    """The optimized motion at K + 1 instants: times (K+1,), q, v, a, tau (K+1, n_dof); its cost
    J (s), the solver's status and iteration count, and the winning initial guess; ``rivals``:
    the fine-grid solutions to the other goals (the elbow a revolution either way) whose coarse
    cost came close, costlier on the fine grid, for a comparison on exact terms (the bang-bang
    refinement); the same goal's cost on the coarse grid (``coarse_intervals``), for the estimate
    of the fine grid's error (``extrapolated_cost``)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    cost: float
    status: str
    iterations: int
    initial_guess: str
    solve_s: float
    rivals: tuple[CollocationResult, ...] = ()
    coarse_cost: float | None = None
    coarse_intervals: int = 0

    def extrapolated_cost(self) -> float | None:
        """The optimum J* of the collocation's problem toward this result's goal (s), estimated
        from the cost J_c on the coarse grid (K_c intervals) and J_K on this grid (K intervals)
        by Richardson's extrapolation at first order,

            J* ~ J_K - |J_c - J_K| K_c / (K - K_c),

        as for an error that shrinks in proportion to the interval: the torques are collocated
        at the instants, and a bang-bang optimum's switches fall between them. It lies below
        the optimum in every case measured (the Geering arm's goals on 20 to 100 intervals,
        whose costs converge at order 0.9 to 1.7, ur5's free motion and Yamamoto's at order 2,
        whose errors it overstates). ``None`` when there is no coarse cost or this grid is no
        finer."""
        intervals = len(self.t) - 1
        if self.coarse_cost is None or intervals <= self.coarse_intervals:
            return None
        return self.cost - abs(self.coarse_cost - self.cost) * self.coarse_intervals / (intervals - self.coarse_intervals)

    def gap_of(self, value: float) -> StatedGap:
        """The estimated relative distance of ``value``, the returned motion's objective (its
        re-timed duration, or cost with a torque weight; s), from the optimum of the
        collocation's problem: (value - J*) / J* (at least 0), J* the least ``extrapolated_cost``
        of this goal and of the ``rivals`` (another goal's optimum may lie lower)."""
        intervals = len(self.t) - 1
        optima = [cost for cost in (one.extrapolated_cost() for one in (self, *self.rivals)) if cost is not None]
        if not optima:
            return StatedGap(None, f"none: no collocation grid coarser than the {intervals} intervals to compare with")
        optimum = min(optima)
        if not optimum > 0.0:
            return StatedGap(None, (
                f"none: the collocation's costs on {self.coarse_intervals} and {intervals} intervals differ too much to "
                "extrapolate; more collocation intervals give an estimate"
            ))
        basis = (
            f"second grid: the collocation's cost on {self.coarse_intervals} and {intervals} intervals, "
            f"extrapolated at first order to an optimum of {optimum:.6g} s"
        )
        return StatedGap(max(0.0, (value - optimum) / optimum), basis)


class StatedGap(NamedTuple):
    """An answer's estimated relative distance from its method's optimum (``None``: not
    estimated) and how it was estimated."""

    optimality_gap: float | None
    gap_basis: str


def collocation_path(result: CollocationResult) -> tuple[ViaPath, ConstantSpeedTiming]:
    """The optimized motion as a path with constant-speed timing: on each interval the exact
    cubic q_k + v_k t + a_k t^2 / 2 + (a_k+1 - a_k) t^3 / (6 h)."""
    from toptraj.planners.generators.via_points import ConstantSpeedTiming, ViaPath

    h = np.diff(result.t)
    jerk_term = (result.a[1:] - result.a[:-1]) / (6 * h[:, None])
    zeros = np.zeros_like(jerk_term)
    coefficients = np.stack([result.q[:-1], result.v[:-1], result.a[:-1] / 2, jerk_term, zeros, zeros], axis=2)
    path = ViaPath(coefficients, h)
    return path, ConstantSpeedTiming(path.total, path.knots)
