"""The grid of s (``toptraj.planners.paths.grid.path_grid``): knots held, segments spaced as np.linspace
spaces them, bad knots refused."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from toptraj.planners.errors import TimingFailed
from toptraj.planners.paths.grid import MIN_POINTS_PER_SEGMENT, on_points, path_grid, spread_indices


@pytest.mark.parametrize("n_intervals", [None, 25, 100, 1000])
def test_each_segment_is_spaced_as_linspace_spaces_it(n_intervals):
    rng = np.random.default_rng(3)
    for _ in range(20):
        knots = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, int(rng.integers(1, 12)))), [1.0]])
        s = path_grid(SimpleNamespace(knots=knots), n_intervals)
        at = np.searchsorted(s, knots)
        np.testing.assert_array_equal(s[at], knots)  # every knot is a grid point
        for start, end, first, last in zip(knots[:-1], knots[1:], at[:-1], at[1:]):
            count = last - first
            assert count >= MIN_POINTS_PER_SEGMENT
            np.testing.assert_array_equal(s[first:last], np.linspace(start, end, count + 1)[:-1])


@pytest.mark.parametrize(
    "knots",
    [[0.0], [0.0, 0.5, 0.5, 1.0], [0.0, 0.7, 0.3, 1.0], [0.0, np.nan, 1.0], [0.0, np.inf], [-np.inf, 1.0], [[0.0, 1.0]]],
)
def test_knots_that_are_no_increasing_finite_sequence_are_refused(knots):
    with pytest.raises(TimingFailed, match="not an increasing sequence"):
        path_grid(SimpleNamespace(knots=np.asarray(knots, dtype=float)), 25)


def test_spread_indices_are_the_rounded_evenly_spaced_rows_without_repeats():
    """At most ``most`` rows from the first to the last, evenly spread: the rounded positions
    of ``np.linspace`` with repeats removed (never any to remove), every row when there are
    few enough."""
    for n in range(1, 260):
        for most in (1, 2, 3, 7, 100, 200):
            expected = np.unique(np.linspace(0, n - 1, min(n, most)).round().astype(int))
            np.testing.assert_array_equal(spread_indices(n, most), expected)


def test_on_points_is_membership_in_an_increasing_grid():
    rng = np.random.default_rng(3)
    grid = np.unique(rng.integers(0, 50, 20)) / 50.0
    values = rng.integers(-5, 55, 200) / 50.0
    np.testing.assert_array_equal(on_points(values, grid), np.isin(values, grid))
    assert not on_points(values, np.empty(0)).any()
