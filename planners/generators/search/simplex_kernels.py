"""Nelder-Mead over the compiled objective of the local optimization
(``toptraj.planners.generators.search.local``, ``objective_kernels.objective_value``) in one
compiled loop: SciPy's ``_minimize_neldermead`` (Nelder & Mead 1965; with ``adaptive``, Gao &
Han 2012's coefficients for n variables: reflection 1, expansion 1 + 2/n, contraction
3/4 - 1/(2n), shrink 1 - 1/n) step for step, the same arithmetic in the same order, so that
it walks the same simplices and spends the same evaluations, without a Python call per
evaluation (a tenth of an evaluation's time on the two-joint arm).

What SciPy does, and so this loop: the vertices (N + 1, N) sorted by objective (``fsim``,
(N + 1,)); each iteration stops first when the simplex has converged (every vertex within
``xatol`` of the best, every objective within ``fatol``), then reflects the worst vertex through
the centroid of the others (the centroid summed row by row, as ``np.add.reduce`` over axis 0),
expands, contracts outside or inside, or shrinks toward the best, and sorts again. An
evaluation beyond ``maxfev`` is not made: the iteration ends where it would have been, the
vertices are sorted, and the loop stops (SciPy's ``_MaxFuncCallError``). With distinct
objectives every sort gives the same order, so the loop sorts itself (insertion); where two
are equal (a control point that moves no limit and no distance, as a wrist turning its
symmetric tool), NumPy's sort, which SciPy calls and which need not be stable, orders them:
the loop returns with ``UNSORTED`` and the caller sorts with ``np.argsort``.

``iterate`` returns after ``chunk`` evaluations or more (at the end of an iteration), so that
the caller checks its deadline and allowance between chunks. ``counters`` holds (evaluations,
iterations); ``best`` and ``best_x`` the least objective evaluated and its point.
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.generators.search.objective_kernels import objective_value

# counters
CALLS, ITERATIONS = 0, 1
# what ``iterate`` stopped at, and the flag of vertices left for the caller to sort
GOING, CONVERGED, MAXFEV, UNSORTED = 0, 1, 2, 4


@njit(cache=True, nogil=True)
def _evaluate(x, counters, best, best_x, maxfev, fixed):  # pragma: no cover - compiled
    """The objective at x, or (False, nan) when ``maxfev`` evaluations are spent."""
    if counters[CALLS] >= maxfev:
        return False, np.nan
    counters[CALLS] += 1
    value = objective_value(x.copy(), *fixed)
    if value < best[0]:
        best[0] = value
        best_x[:] = x
    return True, value


@njit(cache=True, nogil=True)
def _sort(sim, fsim):  # pragma: no cover - compiled
    """Vertices and objectives in increasing order of objective; False, and nothing moved,
    where two objectives are equal or one is nan (the caller sorts as NumPy does)."""
    n = fsim.shape[0]
    order = np.arange(n)
    for i in range(1, n):
        j = i
        while j > 0 and fsim[order[j]] < fsim[order[j - 1]]:
            order[j], order[j - 1] = order[j - 1], order[j]
            j -= 1
    for i in range(n):
        if np.isnan(fsim[i]) or (i > 0 and not fsim[order[i - 1]] < fsim[order[i]]):
            return False
    sim[:] = sim[order].copy()
    fsim[:] = fsim[order].copy()
    return True


@njit(cache=True, nogil=True)
def start(sim, fsim, counters, best, best_x, maxfev, begin, end, fixed):  # pragma: no cover - compiled
    """The objectives of the first simplex's vertices ``begin`` to ``end`` - 1; after the last
    vertex, the vertices sorted (``GOING``), or left for the caller to sort twice as SciPy does
    (``GOING | UNSORTED``)."""
    for k in range(begin, end):
        ok, value = _evaluate(sim[k], counters, best, best_x, maxfev, fixed)
        if not ok:
            break
        fsim[k] = value
    if end == sim.shape[0] and not _sort(sim, fsim):
        return GOING | UNSORTED
    return GOING


@njit(cache=True, nogil=True)
def _converged(sim, fsim, xatol, fatol):  # pragma: no cover - compiled
    """SciPy's test: every vertex within ``xatol`` of the best and every objective within
    ``fatol`` of its (a nan anywhere, as ``np.max`` propagates it, is no convergence)."""
    worst_x, worst_f = 0.0, 0.0
    for k in range(1, sim.shape[0]):
        for j in range(sim.shape[1]):
            step = abs(sim[k, j] - sim[0, j])
            if np.isnan(step):
                return False
            worst_x = max(worst_x, step)
        gap = abs(fsim[0] - fsim[k])
        if np.isnan(gap):
            return False
        worst_f = max(worst_f, gap)
    return worst_x <= xatol and worst_f <= fatol


@njit(cache=True, nogil=True)
def _step(sim, fsim, counters, best, best_x, maxfev, rho, chi, psi, sigma, fixed):  # pragma: no cover - compiled
    """One iteration (reflect, expand, contract or shrink); False where it stopped at ``maxfev``."""
    n = sim.shape[1]
    xbar = sim[0].copy()
    for k in range(1, n):
        xbar += sim[k]
    xbar /= n
    worst = sim[n].copy()
    xr = (1 + rho) * xbar - rho * worst
    ok, fxr = _evaluate(xr, counters, best, best_x, maxfev, fixed)
    if not ok:
        return False
    if fxr < fsim[0]:
        xe = (1 + rho * chi) * xbar - rho * chi * worst
        ok, fxe = _evaluate(xe, counters, best, best_x, maxfev, fixed)
        if not ok:
            return False
        sim[n], fsim[n] = (xe, fxe) if fxe < fxr else (xr, fxr)
    elif fxr < fsim[n - 1]:
        sim[n], fsim[n] = xr, fxr
    else:
        shrink = False
        if fxr < fsim[n]:
            xc = (1 + psi * rho) * xbar - psi * rho * worst
            ok, fxc = _evaluate(xc, counters, best, best_x, maxfev, fixed)
            if not ok:
                return False
            if fxc <= fxr:
                sim[n], fsim[n] = xc, fxc
            else:
                shrink = True
        else:
            xcc = (1 - psi) * xbar + psi * worst
            ok, fxcc = _evaluate(xcc, counters, best, best_x, maxfev, fixed)
            if not ok:
                return False
            if fxcc < fsim[n]:
                sim[n], fsim[n] = xcc, fxcc
            else:
                shrink = True
        if shrink:
            for j in range(1, n + 1):
                sim[j] = sim[0] + sigma * (sim[j] - sim[0])
                ok, value = _evaluate(sim[j], counters, best, best_x, maxfev, fixed)
                if not ok:
                    return False
                fsim[j] = value
    return True


@njit(cache=True, nogil=True)
def iterate(sim, fsim, counters, best, best_x, maxfev, xatol, fatol, rho, chi, psi, sigma, chunk, fixed):  # pragma: no cover - compiled
    """Iterations until convergence, ``maxfev`` or ``chunk`` more evaluations: what stopped it,
    with ``UNSORTED`` where the caller must sort the vertices first (equal objectives)."""
    until = counters[CALLS] + chunk
    while counters[CALLS] < maxfev:
        if _converged(sim, fsim, xatol, fatol):
            return CONVERGED
        done = _step(sim, fsim, counters, best, best_x, maxfev, rho, chi, psi, sigma, fixed)
        if done:
            counters[ITERATIONS] += 1
        status = GOING if done else MAXFEV
        if not _sort(sim, fsim):
            return status | UNSORTED
        if not done or counters[CALLS] >= until:
            return status
    return MAXFEV
