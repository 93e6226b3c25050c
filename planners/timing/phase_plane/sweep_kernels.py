"""Compiled sweeps of the phase-plane method (numba): the backward sweep of the controllable
sets from the end state, the forward sweep of maximum acceleration under them, and ``sweeps``,
one solve on a grid from the interval bounds of ``toptraj.planners.constraints.admissible_kernels``. Each sweep is sequential
along the path; a step costs one pass over the rows of its interval.

Bounds on u come as in ``toptraj.planners.constraints.admissible_kernels``: lines ``p + q x <= u <= r + q x`` per row, (N, m),
the lower and upper line of a row sharing the slope q; -inf (p) or +inf (r) where a row gives no
such bound.
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.constraints.admissible_kernels import interval_bounds
from toptraj.planners.timing.phase_plane.refinement_kernels import switch_excess

_INF = np.inf


@njit(cache=True, nogil=True)
def backward_envelope(ds, p, q, r, x_low, x_high, x_end, slack):  # pragma: no cover - compiled
    """The controllable sets, swept backward from the end state: for i = N-1 .. 0 the interval
    [lower_i, upper_i] of admissible x_i from which some u in [alpha_i(x_i), beta_i(x_i)] lands
    x_i + 2 ds_i u inside [lower_i+1, upper_i+1]. The upper end uses the least u (maximum
    deceleration, u = max_k p_k + q_k x), the lower end the greatest (u = min_j r_j + q_j x).

    Returns upper (N + 1,), lower (N + 1,) and the index of the first interval (from the end)
    whose set is empty, or -1.
    """
    n_stages, n_rows = p.shape
    upper = np.empty(n_stages + 1)
    lower = np.empty(n_stages + 1)
    upper[n_stages] = x_end
    lower[n_stages] = x_end
    for i in range(n_stages - 1, -1, -1):
        step = 2.0 * ds[i]
        ceiling = upper[i + 1]
        floor = lower[i + 1]
        high = x_high[i]
        low = x_low[i]
        for k in range(n_rows):
            pk = p[i, k]
            rk = r[i, k]
            # x + step (p_k + q_k x) <= ceiling and x + step (r_k + q_k x) >= floor: both lines
            # share the slope, so one division serves both bounds on x.
            denominator = 1.0 + step * q[i, k]
            if denominator > 0.0:
                inverse = 1.0 / denominator
                if pk != -_INF:
                    bound = (ceiling - step * pk) * inverse
                    if bound < high:
                        high = bound
                if rk != _INF:
                    bound = (floor - step * rk) * inverse
                    if bound > low:
                        low = bound
            elif denominator < 0.0:
                inverse = 1.0 / denominator
                if pk != -_INF:
                    bound = (ceiling - step * pk) * inverse
                    if bound > low:
                        low = bound
                if rk != _INF:
                    bound = (floor - step * rk) * inverse
                    if bound < high:
                        high = bound
            else:
                if pk != -_INF and ceiling - step * pk < 0.0:
                    high = -1.0
                if rk != _INF and floor - step * rk > 0.0:
                    high = -1.0
        upper[i] = high
        lower[i] = low
        if high < low - slack * (1.0 + abs(low)):
            return upper, lower, i
    return upper, lower, -1


@njit(cache=True, nogil=True)
def forward_profile(ds, r, q, envelope, x_start):  # pragma: no cover - compiled
    """Maximum-acceleration sweep from the start (u = min_j r_j + q_j x), capped by the
    envelope: x (N + 1,) and, per interval, whether the cap decided it (True) or the
    acceleration limit did (False)."""
    n_stages, n_rows = r.shape
    x = np.empty(n_stages + 1)
    capped = np.zeros(n_stages, dtype=np.bool_)
    x[0] = x_start
    for i in range(n_stages):
        xi = x[i]
        fastest = _INF
        for k in range(n_rows):
            value = r[i, k] + q[i, k] * xi
            if value < fastest:
                fastest = value
        reach = xi + 2.0 * ds[i] * fastest
        if reach >= envelope[i + 1]:
            x[i + 1] = envelope[i + 1]
            capped[i] = True
        else:
            x[i + 1] = reach if reach > 0.0 else 0.0
    return x, capped


@njit(cache=True, nogil=True)
def sweeps(s, ra, rb, rc, rd, la, lb, lc, ld, lower, upper, x_bound, x_ref, friction, x_start, x_end, midpoint, slack, kept, before):  # pragma: no cover - compiled
    """One solve on the grid ``s`` (N + 1,): the interval bounds (``interval_bounds``, whose
    arguments these are, ``kept`` and ``before`` the bounds of an earlier grid's intervals that
    this grid keeps), the backward envelope from ``x_end`` and the forward profile from
    ``min(x_start, envelope_0)``.

    Returns x (N + 1,; empty when the backward sweep failed), capped (N,), envelope and floor
    (N + 1,), the index of the interval where the backward sweep failed or -1, the admissible
    upper x_i of each interval (N,), the ``switch_excess`` of each interval (N,; zeros in the
    midpoint discretization, whose profile only serves the conservative one as a reference) and
    the interval bounds (p, q, r, x_low, x_high: the ``before`` of a refined grid).
    """
    p, q, r, x_low, x_high, _ = interval_bounds(s, ra, rb, rc, rd, la, lb, lc, ld, lower, upper, x_bound, x_ref, friction, midpoint, kept, before)
    bounds = (p, q, r, x_low, x_high)
    n_stages = s.shape[0] - 1
    ds = np.empty(n_stages)
    for i in range(n_stages):
        ds[i] = s[i + 1] - s[i]
    envelope, floor, failed = backward_envelope(ds, p, q, r, x_low, x_high, x_end, slack)
    if failed >= 0:
        return np.empty(0), np.empty(0, dtype=np.bool_), envelope, floor, failed, x_high, np.empty(0), bounds
    x, capped = forward_profile(ds, r, q, envelope, min(x_start, envelope[0]))
    if midpoint:
        return x, capped, envelope, floor, failed, x_high, np.zeros(n_stages), bounds
    ceiling = np.empty(n_stages + 1)
    ceiling[:n_stages] = x_high
    ceiling[n_stages] = max(x_bound[n_stages], x_end) if x_bound[n_stages] < _INF else x_high[n_stages - 1]
    return x, capped, envelope, floor, failed, x_high, switch_excess(ds, p, q, r, x, ceiling), bounds
