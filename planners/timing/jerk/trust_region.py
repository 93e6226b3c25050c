"""The trust-region sequential linear programming of the jerk-limited timing's polish
(``toptraj.planners.timing.jerk.polish``): minimize the sum of the segments' durations subject
to equalities h(z) = 0 (the end state) and inequalities g(z) >= 0 (the limits at the check
points), with an exact l1 penalty merit (Fletcher, "Practical Methods of Optimization", 2nd ed.,
1987, sections 12.3 and 14.5: the l1 exact penalty function and the second-order correction),
each LP solved by HiGHS.

The variables z (2 M,) are the M durations (scaled, s) then the M path jerks (scaled, 1/s^3);
``evaluate(z)`` returns h (3,), its Jacobian H (3, 2 M), g (m,) and G (m, 2 M).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def solve_penalized(
    z: np.ndarray, evaluate: Callable[[np.ndarray], tuple], M: int, max_iterations: int, give_up_after: int,
) -> np.ndarray | None:
    """Minimize the sum of the (scaled) durations z[:M] subject to h(z) = 0 and g(z) >= 0:
    sequential linear programming in a trust region with an exact (l1) penalty merit, each LP
    step followed by a second-order correction onto the rows it holds with equality (a
    least-norm Newton step), which keeps the steps on the curved constraint surfaces, so that
    they are not rejected for their second-order violation. Rows of g that repeat another row
    (a jerk row along a segment whose limits do not change, a limit at the state two segments
    share) are kept once. ``None`` when it does not end at a feasible point, or (after
    ``give_up_after`` LPs) is still far from one."""
    _, _, g, G = evaluate(z)
    keep = _distinct_rows(np.column_stack([g, G]))
    radius = 0.5
    cost = np.concatenate([np.ones(M), np.zeros(M)])

    def state(z):
        h, H, g, G = evaluate(z)
        return h, H, g[keep], G[keep]

    def merit(h, g, z):
        return float(cost @ z + _PENALTY * (np.abs(h).sum() + np.maximum(-g, 0.0).sum()))

    h, H, g, G = state(z)
    current = merit(h, g, z)
    for iteration in range(max_iterations):
        violation = max(np.abs(h).max(), -g.min() if len(g) else 0.0)
        if iteration >= give_up_after and violation > 1e-3:
            return None  # the segments cannot follow these limits: keep the grid solution
        step = _step(z, h, H, g, G, cost, radius)
        if step is None:
            return None
        step, predicted = step[0], current - step[1]
        if predicted <= 1e-14 * max(1.0, abs(current)):
            break
        trial = _corrected(z, step, state, H, g, G, radius)
        trial[:M] = np.maximum(trial[:M], 0.0)
        h_t, H_t, g_t, G_t = state(trial)
        actual = current - merit(h_t, g_t, trial)
        if actual >= 0.1 * predicted:
            z, h, H, g, G, current = trial, h_t, H_t, g_t, G_t, merit(h_t, g_t, trial)
            if actual >= 0.75 * predicted and np.abs(step).max() >= 0.99 * radius:
                radius = min(2.0 * radius, 10.0)
        else:
            radius *= 0.25
            if radius < 1e-13:
                break
    if np.abs(h).max() > 1e-9 or (len(g) and g.min() < -1e-9):
        return None
    return z


#: Weight of the l1 penalty on the violated rows in ``solve_penalized``'s merit and LPs.
_PENALTY = 100.0


def _step(z, h, H, g, G, cost, radius: float):
    """The LP of one trust-region step of ``solve_penalized``: min cost.dz + penalty (|e_eq| + e_g) over
    the step dz (within ``radius``, the durations kept >= 0, the jerk of a segment shrunk to
    nothing frozen) and the elastic variables, h + H dz = e_plus - e_minus and
    g + G dz + e_g >= 0. Returns (dz, the model's merit at z + dz), or ``None`` when HiGHS
    finds no optimum."""
    import highspy
    from scipy import sparse  # here: scipy.sparse is imported by jerk_limited only

    M = len(z) // 2
    n, m_eq, m_in = 2 * M, len(h), len(g)
    # Columns: dz (n), e_plus (m_eq), e_minus (m_eq), e_g (m_in).
    objective = np.concatenate([cost, np.full(2 * m_eq + m_in, _PENALTY)])
    # The jerk of a segment that has shrunk to nothing is left where it is: it no longer
    # acts on the motion, and a free variable that does nothing makes the LPs degenerate.
    frozen = np.concatenate([np.zeros(M, dtype=bool), z[:M] <= 1e-9])
    lower = np.concatenate([np.maximum(-radius, -z[:M]), np.full(M, -radius), np.zeros(2 * m_eq + m_in)])
    upper = np.concatenate([np.full(n, radius), np.full(2 * m_eq + m_in, np.inf)])
    lower[:n][frozen] = upper[:n][frozen] = 0.0
    csc = sparse.bmat([
        [sparse.csr_matrix(H), -sparse.identity(m_eq), sparse.identity(m_eq), None],
        [sparse.csr_matrix(G), None, None, sparse.identity(m_in)],
    ], format="csc")
    solver = highspy.Highs()
    solver.setOptionValue("output_flag", False)
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = len(objective), csc.shape[0]
    lp.col_cost_, lp.col_lower_, lp.col_upper_ = objective, lower, upper
    lp.row_lower_ = np.concatenate([-h, -g])
    lp.row_upper_ = np.concatenate([-h, np.full(m_in, np.inf)])
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = csc.indptr, csc.indices, csc.data
    solver.passModel(lp)
    solver.run()
    if solver.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return None
    solution = np.asarray(solver.getSolution().col_value)
    return solution[:n], float(objective @ solution + cost @ z)


def _corrected(z, step, state, H, g, G, radius: float):
    """z + step, corrected back onto the rows the LP step holds with equality (and h = 0) by a
    least-norm Newton step, when that correction stays within ``radius``."""
    active = np.flatnonzero(np.abs(g + G @ step) <= 1e-9 * (1.0 + np.abs(G).max(axis=1) * radius))
    trial = z + step
    h_t, _, g_t, _ = state(trial)
    system = np.vstack([H, G[active]])
    if system.shape[0]:
        correction = np.linalg.lstsq(system, -np.concatenate([h_t, g_t[active]]), rcond=None)[0]
        if np.abs(correction).max() <= radius:
            trial = trial + correction
    return trial


def _distinct_rows(rows: np.ndarray, tolerance: float = 1e-9) -> np.ndarray:
    """Indices of the rows of ``rows`` (m, k) that repeat no earlier row within ``tolerance``
    (relative to the larger magnitude of the two)."""
    scale = np.maximum(np.abs(rows).max(axis=1), 1e-300)
    keep: list[int] = []
    for i in range(len(rows)):
        if keep:
            kept = np.asarray(keep)
            gap = np.abs(rows[kept] - rows[i]).max(axis=1) / np.maximum(scale[kept], scale[i])
            if gap.min() <= tolerance:
                continue
        keep.append(i)
    return np.asarray(keep, dtype=int)
