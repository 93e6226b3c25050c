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
def _gap(p, q, r, w, i, x):  # pragma: no cover - compiled
    """phi(x) = min_j (r_j + w_j x) - max_k (p_k + q_k x) at point i, its slope there, and the
    intercept of the active piece (so its root is -intercept / slope without cancellation)."""
    n_rows = p.shape[1]
    lowest = -_INF
    low_slope = 0.0
    low_intercept = 0.0
    highest = _INF
    high_slope = 0.0
    high_intercept = 0.0
    for k in range(n_rows):
        if p[i, k] != -_INF:
            value = p[i, k] + q[i, k] * x
            if value > lowest:
                lowest = value
                low_slope = q[i, k]
                low_intercept = p[i, k]
        if r[i, k] != _INF:
            value = r[i, k] + w[i, k] * x
            if value < highest:
                highest = value
                high_slope = w[i, k]
                high_intercept = r[i, k]
    return highest - lowest, high_slope - low_slope, high_intercept - low_intercept


#: Stand-in for an unbounded x = sd^2 in the root search (sd = 1e6 1/s).
_X_FAR = 1e12


@njit(cache=True)
def admissible_intervals(p, q, r, w, x_low, x_high):  # pragma: no cover - compiled
    """Narrow ``[x_low, x_high]`` (each (N,), updated in place and returned) at every point to
    the x for which some u lies between every lower and every upper line.

    phi(x) = min_j (r_j + w_j x) - max_k (p_k + q_k x) is concave and piecewise linear, and the
    admissible x are where phi >= 0. Started right of the interval (where phi < 0 falls), Newton's
    method on a concave piecewise-linear function steps along one linear piece at a time without
    overshooting the largest root; started left of it, likewise to the smallest root. A few
    steps find each end exactly. An empty interval is marked by x_high = -1.
    """
    n_points = p.shape[0]
    for i in range(n_points):
        low = x_low[i]
        high = x_high[i]
        unbounded = high > _X_FAR
        x = _X_FAR if unbounded else high
        if x < low:
            x_high[i] = -1.0
            continue
        empty = False
        for _ in range(100):
            gap, slope, intercept = _gap(p, q, r, w, i, x)
            if gap >= -1e-12 * (1.0 + abs(x)):
                break
            if slope >= 0.0:
                empty = True
                break
            x = -intercept / slope
            if x < low - 1e-12 * (1.0 + abs(low)):
                empty = True
                break
        if empty:
            x_high[i] = -1.0
            continue
        x_high[i] = high if (unbounded and x == _X_FAR) else x
        x = low
        for _ in range(100):
            gap, slope, intercept = _gap(p, q, r, w, i, x)
            if gap >= -1e-12 * (1.0 + abs(x)):
                break
            if slope <= 0.0:
                x_high[i] = -1.0
                break
            x = -intercept / slope
        x_low[i] = x
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
