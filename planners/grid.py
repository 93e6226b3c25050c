"""The grid of s on which constraints are evaluated and paths are timed."""

from __future__ import annotations

import numpy as np

from planners.errors import TimingFailed
from planners.paths.base import GeometricPath

#: Intervals per path segment (between consecutive knots) when the request names no grid size.
DEFAULT_POINTS_PER_SEGMENT = 100
MIN_POINTS = 100
MAX_POINTS = 20_000


def path_grid(path: GeometricPath, n_intervals: int | None = None) -> np.ndarray:
    """An increasing grid over [0, 1] holding every knot of ``path``, with about ``n_intervals``
    intervals (default: ``DEFAULT_POINTS_PER_SEGMENT`` per segment) spread evenly over s."""
    knots = path.knots
    if not (np.all(np.isfinite(knots)) and np.all(np.diff(knots) >= 0.0)):
        raise TimingFailed(
            "the path's segment boundaries in s are not an increasing sequence of finite numbers "
            "(its segment lengths or durations overflowed); check the request's durations and limits"
        )
    if n_intervals is None:
        n_intervals = max(MIN_POINTS, DEFAULT_POINTS_PER_SEGMENT * (len(knots) - 1))
    n_intervals = int(min(max(n_intervals, len(knots) - 1), MAX_POINTS))
    pieces = []
    for start, end in zip(knots[:-1], knots[1:]):
        count = max(1, int(round(n_intervals * (end - start))))
        pieces.append(np.linspace(start, end, count + 1)[:-1])
    pieces.append([1.0])
    return np.concatenate(pieces)
