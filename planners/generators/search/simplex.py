"""One round of Nelder-Mead of the local optimization (``toptraj.planners.generators.search.local``)
in compiled chunks (``simplex_kernels``): the same simplices and evaluations as SciPy's
``minimize(method="Nelder-Mead")`` with an initial simplex, ``maxfev``, ``xatol``, ``fatol`` and
``adaptive``, for an objective that takes the fused path (``local_objective.Objective.fused``).

Between chunks of ``CHUNK_EVALUATIONS`` evaluations the deadline and the allowance are checked
(SciPy's loop, through ``Objective.__call__``, checks them at every evaluation): once the
allowance is spent, the round ends at the best point evaluated so far.
"""

from __future__ import annotations

import time

import numpy as np

from toptraj.planners.generators.search import simplex_kernels as kernels
from toptraj.planners.generators.search.local_objective import Objective

#: Evaluations between two checks of the deadline and the allowance (about 6 ms on the
#: two-joint arm, 0.1 s on a seven-joint one).
CHUNK_EVALUATIONS = 32


def _coefficients(n: int, adaptive: bool) -> tuple[float, float, float, float]:
    """rho, chi, psi, sigma (reflection, expansion, contraction, shrink) as SciPy takes them:
    Gao & Han's for ``n`` variables when ``adaptive``, else the classic 1, 2, 1/2, 1/2."""
    if not adaptive:
        return 1.0, 2.0, 0.5, 0.5
    dim = float(n)
    return 1.0, 1 + 2 / dim, 0.75 - 1 / (2 * dim), 1 - 1 / dim


def compiled_nelder_mead(
    objective: Objective, simplex: np.ndarray, maxfev: int, xatol: float, fatol: float, adaptive: bool
) -> tuple[np.ndarray | None, float, bool]:
    """Nelder-Mead from ``simplex`` (N + 1, N): the best point and its objective, and whether
    the allowance was spent (then the best point evaluated, ``None`` when there is none).
    ``objective.evaluations`` counts the evaluations made."""
    sim = np.array(simplex, dtype=float, copy=True)
    n = sim.shape[1]
    fsim = np.full(n + 1, np.inf)
    counters = np.zeros(2, dtype=np.int64)
    best, best_x = np.array([np.inf]), np.empty(n)
    fixed = objective.fused_arguments()
    status, counted = kernels.GOING, 0
    try:
        for begin in range(0, n + 1, CHUNK_EVALUATIONS):
            _check(objective)
            status = kernels.start(sim, fsim, counters, best, best_x, maxfev, begin, min(begin + CHUNK_EVALUATIONS, n + 1), fixed)
            objective.evaluations += int(counters[kernels.CALLS]) - counted
            counted = int(counters[kernels.CALLS])
        if status & kernels.UNSORTED:
            _numpy_sort(sim, fsim)
            _numpy_sort(sim, fsim)
        status = kernels.GOING
        while status == kernels.GOING:
            _check(objective)
            status = kernels.iterate(sim, fsim, counters, best, best_x, maxfev, xatol, fatol, *_coefficients(n, adaptive), CHUNK_EVALUATIONS, fixed)
            objective.evaluations += int(counters[kernels.CALLS]) - counted
            counted = int(counters[kernels.CALLS])
            if status & kernels.UNSORTED:
                _numpy_sort(sim, fsim)
                status &= ~kernels.UNSORTED
    except _Spent:
        return (best_x if np.isfinite(best[0]) else None), float(best[0]), True
    return sim[0].copy(), float(np.min(fsim)), False


def _numpy_sort(sim: np.ndarray, fsim: np.ndarray) -> None:
    """The vertices in the order SciPy's loop sorts them (``np.argsort``, ``np.take``)."""
    order = np.argsort(fsim)
    sim[:] = np.take(sim, order, 0)
    fsim[:] = np.take(fsim, order, 0)


class _Spent(Exception):
    """The allowance is spent."""


def _check(objective: Objective) -> None:
    objective.deadline.check()
    if time.monotonic() > objective.stop_at:
        raise _Spent
