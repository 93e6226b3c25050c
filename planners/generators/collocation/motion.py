"""The collocation's answer (``toptraj.planners.generators.collocation.collocation``, Jeong &
Lee section 4): the motion at its K + 1 instants with its torques, its cost and how the solver
got there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

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
    of the fine grid's error."""

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

    @property
    def optimality_gap(self) -> float | None:
        """Estimated relative distance of the cost from the optimum of the collocation's problem
        (its goal): the difference from the same goal's solution on the coarse grid, which
        bounds the fine grid's error from above where the error shrinks with the interval.
        ``None`` when unknown."""
        if self.coarse_cost is None:
            return None
        return max(0.0, (self.coarse_cost - self.cost) / self.cost)

    @property
    def gap_basis(self) -> str:
        """How ``optimality_gap`` was obtained."""
        if self.coarse_cost is None:
            return "none"
        return f"second grid: the cost on {self.coarse_intervals} intervals against {len(self.t) - 1}"


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
