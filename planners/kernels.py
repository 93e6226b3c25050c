"""Compiled inner loops of the phase-plane method (numba): the per-point admissible interval of
x = sd^2 and the two sequential sweeps. Plain loops over small row counts, compiled once and
cached on disk; they hold no knowledge of paths or robots.

Bounds on the path acceleration u come as lines: ``p + q x <= u <= r + w x`` per row, shape
(N, m), with an intercept of -inf (p) or +inf (r) where a row gives no such bound.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_INF = np.inf


@njit(cache=True)
def admissible_intervals(p, q, r, w, x_low, x_high):  # pragma: no cover - compiled
    """Narrow ``[x_low, x_high]`` (each (N,), updated in place and returned) at every point to
    the x for which some u lies between every lower and every upper line: for each pair,
    p_k + q_k x <= r_j + w_j x."""
    n_points, n_rows = p.shape
    for i in range(n_points):
        low = x_low[i]
        high = x_high[i]
        for k in range(n_rows):
            pk = p[i, k]
            if pk == -_INF:
                continue
            qk = q[i, k]
            for j in range(n_rows):
                rj = r[i, j]
                if rj == _INF:
                    continue
                alpha = qk - w[i, j]
                beta = rj - pk
                if alpha > 0.0:
                    bound = beta / alpha
                    if bound < high:
                        high = bound
                elif alpha < 0.0:
                    bound = beta / alpha
                    if bound > low:
                        low = bound
                elif beta < 0.0:
                    high = -1.0
        x_low[i] = low
        x_high[i] = high
    return x_low, x_high


@njit(cache=True)
def backward_envelope(ds, p, q, r, w, x_low, x_high, x_end, slack):  # pragma: no cover - compiled
    """The controllable sets, swept backward from the end state: for i = N-1 .. 0 the interval
    [lower_i, upper_i] of admissible x_i from which some u in [alpha_i(x_i), beta_i(x_i)] lands
    x_i + 2 ds_i u inside [lower_i+1, upper_i+1]. The upper end uses the least u (maximum
    deceleration, u = max_k p_k + q_k x), the lower end the greatest (u = min_j r_j + w_j x).

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
            if pk != -_INF:
                # x + step (p_k + q_k x) <= ceiling
                denominator = 1.0 + step * q[i, k]
                numerator = ceiling - step * pk
                if denominator > 0.0:
                    if numerator / denominator < high:
                        high = numerator / denominator
                elif denominator < 0.0:
                    if numerator / denominator > low:
                        low = numerator / denominator
                elif numerator < 0.0:
                    high = -1.0
            rk = r[i, k]
            if rk != _INF:
                # x + step (r_k + w_k x) >= floor
                denominator = 1.0 + step * w[i, k]
                numerator = floor - step * rk
                if denominator > 0.0:
                    if numerator / denominator > low:
                        low = numerator / denominator
                elif denominator < 0.0:
                    if numerator / denominator < high:
                        high = numerator / denominator
                elif numerator > 0.0:
                    high = -1.0
        upper[i] = high
        lower[i] = low
        if high < low - slack * (1.0 + abs(low)):
            return upper, lower, i
    return upper, lower, -1


@njit(cache=True)
def forward_profile(ds, r, w, envelope, x_start):  # pragma: no cover - compiled
    """Maximum-acceleration sweep from the start, capped by the envelope: x (N + 1,) and, per
    interval, whether the cap decided it (True) or the acceleration limit did (False)."""
    n_stages, n_rows = r.shape
    x = np.empty(n_stages + 1)
    capped = np.zeros(n_stages, dtype=np.bool_)
    x[0] = x_start
    for i in range(n_stages):
        xi = x[i]
        fastest = _INF
        for k in range(n_rows):
            value = r[i, k] + w[i, k] * xi
            if value < fastest:
                fastest = value
        reach = xi + 2.0 * ds[i] * fastest
        if reach >= envelope[i + 1]:
            x[i + 1] = envelope[i + 1]
            capped[i] = True
        else:
            x[i + 1] = reach if reach > 0.0 else 0.0
    return x, capped
