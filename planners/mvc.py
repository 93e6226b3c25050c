"""The admissible set of the phase plane at each grid point: the interval of x = sd^2 for which
some path acceleration u satisfies every second-order row, capped by the first-order bound.
Its upper end is the maximum velocity curve (MVC), the "velocity limit curve" of Jeong & Lee
section 3.2 (the limit that the torque bounds (3.6) place on mu = lambda-dot).

Each row ``lower <= a u + b x + c <= upper`` with a != 0 bounds u between two functions linear
in x, l_k(x) <= u <= h_k(x). Some u exists iff l_i(x) <= h_j(x) for every pair (i, j): each pair
is one linear inequality in x, and rows with a = 0 bound x directly. The admissible x therefore
form one interval per grid point, found here for all grid points at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.constraints import LinearRows

#: |a| below this fraction of the row's scale counts as zero (a zero-inertia point).
ZERO_INERTIA = 1e-10


@dataclass(frozen=True)
class AdmissibleSet:
    """Admissible x = sd^2 at each grid point, ``x_min <= x <= x_max`` (shape (N + 1,), 1/s^2).

    ``x_min > x_max`` marks a grid point where no motion at all is admissible; ``blocking_rows``
    then names the rows (indices into the linearized rows) that conflict there, -1 elsewhere.
    """

    x_min: np.ndarray
    x_max: np.ndarray
    blocking_rows: np.ndarray

    @property
    def sd_max(self) -> np.ndarray:
        """The maximum velocity curve, sqrt(x_max), shape (N + 1,), in 1/s."""
        return np.sqrt(np.maximum(self.x_max, 0.0))


def admissible_set(rows: LinearRows, x_bound: np.ndarray) -> AdmissibleSet:
    """Admissible x at every grid point for ``rows`` and the first-order bound ``x <= x_bound``."""
    a, b, c, lower, upper = rows.a, rows.b, rows.c, rows.lower, rows.upper
    n_points, n_rows = a.shape
    scale = np.maximum(np.abs(a) + np.abs(b), 1e-300)
    singular = np.abs(a) <= ZERO_INERTIA * scale
    safe_a = np.where(singular, 1.0, a)
    with np.errstate(invalid="ignore", divide="ignore"):
        # u >= p + q x and u <= r + w x for each row with a != 0.
        from_upper = ((upper - c) / safe_a, -b / safe_a)
        from_lower = ((lower - c) / safe_a, -b / safe_a)
    positive = a > 0
    p = np.where(positive, from_lower[0], from_upper[0])
    r = np.where(positive, from_upper[0], from_lower[0])
    q = w = from_upper[1]
    p = np.where(singular | np.isnan(p), -np.inf, p)
    r = np.where(singular | np.isnan(r), np.inf, r)

    x_min = np.zeros(n_points)
    x_max = np.asarray(x_bound, dtype=float).copy()
    blocking = np.full((n_points, 2), -1)

    # Pairs (i, j): p_i + q_i x <= r_j + w_j x, i.e. (q_i - w_j) x <= r_j - p_i.
    alpha = q[:, :, None] - w[:, None, :]
    beta = r[:, None, :] - p[:, :, None]
    vacuous = ~np.isfinite(beta) & (beta > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = beta / alpha
    upper_cut = np.where((alpha > 0) & ~vacuous, ratio, np.inf)
    lower_cut = np.where((alpha < 0) & ~vacuous, ratio, -np.inf)
    never = (alpha == 0) & (beta < 0) & ~vacuous
    flat_upper = upper_cut.reshape(n_points, -1)
    flat_lower = lower_cut.reshape(n_points, -1)
    x_max = np.minimum(x_max, flat_upper.min(axis=1))
    x_min = np.maximum(x_min, flat_lower.max(axis=1))
    pair_blocked = never.reshape(n_points, -1).any(axis=1)

    # Rows with a = 0 bound x itself: lower <= b x + c <= upper.
    with np.errstate(invalid="ignore", divide="ignore"):
        cut_high = np.where(b > 0, (upper - c) / b, np.where(b < 0, (lower - c) / b, np.inf))
        cut_low = np.where(b > 0, (lower - c) / b, np.where(b < 0, (upper - c) / b, -np.inf))
    static_fail = singular & (b == 0) & ((c > upper) | (c < lower))
    cut_high = np.where(singular & (b != 0), cut_high, np.inf)
    cut_low = np.where(singular & (b != 0), cut_low, -np.inf)
    x_max = np.minimum(x_max, cut_high.min(axis=1))
    x_min = np.maximum(x_min, cut_low.max(axis=1))

    empty = (x_min > x_max) | pair_blocked | static_fail.any(axis=1)
    for point in np.flatnonzero(empty):
        blocking[point] = _blocking_pair(point, p, q, r, w, x_min, static_fail, singular)
    x_max = np.where(empty, -1.0, x_max)
    return AdmissibleSet(x_min=x_min, x_max=x_max, blocking_rows=blocking)


def _blocking_pair(point, p, q, r, w, x_min, static_fail, singular):
    """The two rows whose bounds on u conflict most at ``point`` (at the lowest admissible x)."""
    if static_fail[point].any():
        row = int(np.flatnonzero(static_fail[point])[0])
        return row, row
    x = max(x_min[point], 0.0)
    low = np.where(singular[point], -np.inf, p[point] + q[point] * x)
    high = np.where(singular[point], np.inf, r[point] + w[point] * x)
    return int(np.argmax(low)), int(np.argmin(high))
