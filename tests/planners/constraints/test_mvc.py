"""The admissible set of the phase plane against a linear program solved point by point."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from toptraj.planners.constraints.admissible import admissible_set
from toptraj.planners.constraints.linear_rows import LinearRows

RNG = np.random.default_rng(11)


def _lp_x_range(a, b, c, lower, upper, x_bound):
    """min and max x >= 0 (x <= x_bound) such that some u meets every row, by scipy's HiGHS."""
    finite_upper, finite_lower = np.isfinite(upper), np.isfinite(lower)
    A = np.vstack([np.column_stack([a, b])[finite_upper], -np.column_stack([a, b])[finite_lower]])
    rhs = np.concatenate([(upper - c)[finite_upper], -(lower - c)[finite_lower]])
    bounds = [(None, None), (0.0, None if not np.isfinite(x_bound) else x_bound)]
    low = linprog([0, 1], A_ub=A, b_ub=rhs, bounds=bounds, method="highs")
    high = linprog([0, -1], A_ub=A, b_ub=rhs, bounds=bounds, method="highs")
    if low.status == 2:
        return None
    return low.x[1], (high.x[1] if high.status == 0 else np.inf)


def test_admissible_interval_matches_linear_programming():
    n_points, n_rows = 200, 6
    a = RNG.normal(0, 1, (n_points, n_rows))
    a[::17, 2] = 0.0  # zero-inertia rows
    b = RNG.normal(0, 1, (n_points, n_rows))
    c = RNG.normal(0, 0.6, (n_points, n_rows))
    upper = np.full((n_points, n_rows), 1.0)
    lower = -upper
    x_bound = np.where(RNG.random(n_points) < 0.3, RNG.uniform(0.1, 3, n_points), np.inf)
    result = admissible_set(LinearRows(a, b, c, lower, upper), x_bound)
    checked_empty = checked_full = 0
    for i in range(n_points):
        expected = _lp_x_range(a[i], b[i], c[i], lower[i], upper[i], x_bound[i])
        if expected is None:
            assert result.x_max[i] < result.x_min[i], i
            assert result.blocking_rows[i][0] >= 0
            checked_empty += 1
        else:
            assert result.x_min[i] == pytest.approx(expected[0], abs=1e-7), i
            assert result.x_max[i] == pytest.approx(expected[1], rel=1e-7, abs=1e-7), i
            checked_full += 1
    assert checked_empty > 5 and checked_full > 50
