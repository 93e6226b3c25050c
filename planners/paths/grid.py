"""The grid of s on which constraints are evaluated and paths are timed.

Every stretch of path between two knots (waypoints, breaks of a piecewise definition) is
resolved on its own, however short it is: the knots are grid points, and each stretch gets at
least ``MIN_POINTS_PER_SEGMENT`` intervals. A short stretch of a spline is where its curvature
and third derivative are largest, so spreading points evenly over s would leave exactly the
places where the limits change fastest unsampled.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from toptraj.planners.errors import TimingFailed
from toptraj.planners.paths.base import GeometricPath

#: Intervals per path segment (between consecutive knots) when the request names no grid size.
DEFAULT_POINTS_PER_SEGMENT = 100
#: Fewest intervals of any segment, whatever grid size a request names.
MIN_POINTS_PER_SEGMENT = 8
MIN_POINTS = 100
MAX_POINTS = 20_000


def path_grid(path: GeometricPath, n_intervals: int | None = None) -> np.ndarray:
    """An increasing grid over [0, 1] holding every knot of ``path``.

    Args:
        path: The path; its ``knots`` become grid points.
        n_intervals: About this many intervals, spread over the segments in proportion to their
            length in s, each segment getting at least ``MIN_POINTS_PER_SEGMENT``; ``None``:
            ``DEFAULT_POINTS_PER_SEGMENT`` per segment (at least ``MIN_POINTS`` in all). Either
            way at most ``MAX_POINTS`` intervals, fewer per segment on paths with very many
            segments.

    Returns:
        s, shape (N + 1,), from 0 to 1.
    """
    knots = np.asarray(path.knots, dtype=float)
    lengths = np.diff(knots) if knots.ndim == 1 and len(knots) >= 2 else None
    # Finite ends and positive steps (a NaN anywhere makes the least step NaN): finite throughout.
    if lengths is None or not (lengths.min() > 0.0 and abs(knots[0]) < np.inf and abs(knots[-1]) < np.inf):
        raise TimingFailed(
            "the path's segment boundaries in s are not an increasing sequence of finite numbers "
            "(its segment lengths or durations overflowed); check the request's durations and limits"
        )
    segments = len(lengths)
    floor = max(1, min(MIN_POINTS_PER_SEGMENT, MAX_POINTS // segments))
    if n_intervals is None:
        per_segment = max(floor, min(DEFAULT_POINTS_PER_SEGMENT, MAX_POINTS // segments))
        counts = np.full(segments, max(per_segment, -(-MIN_POINTS // segments)))
    else:
        total = min(max(int(n_intervals), segments), MAX_POINTS)
        counts = np.maximum(floor, np.round(total * lengths).astype(int))
    # Segment k's points knots[k] + j (knots[k+1] - knots[k]) / counts[k], j < counts[k]: the
    # arithmetic of np.linspace, for all segments in one pass.
    segment = np.repeat(np.arange(segments), counts)
    j = np.arange(len(segment)) - np.repeat(np.cumsum(counts) - counts, counts)
    s = np.empty(len(segment) + 1)
    s[:-1] = j * (lengths / counts)[segment] + knots[segment]
    s[-1] = 1.0
    return s


@lru_cache(maxsize=256)
def spread_indices(n: int, most: int) -> np.ndarray:
    """At most ``most`` (>= 1) indices into a sequence of ``n``, evenly spread from the first to
    the last, increasing: every index when ``n <= most``. (With n > most the step
    (n - 1) / (most - 1) exceeds 1, so the rounded positions never repeat.) Read-only, and
    computed once per (n, most): the same few sizes recur from request to request."""
    indices = np.arange(n) if n <= most else np.linspace(0, n - 1, most).round().astype(np.intp)
    indices.setflags(write=False)
    return indices


def on_points(values: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n,) bool: which of ``values`` (n,) equal one of the increasing ``points``: ``np.isin``
    by one binary search per value, without sorting both."""
    values = np.asarray(values, dtype=float)
    if len(points) == 0:
        return np.zeros(values.shape, dtype=bool)
    at = np.minimum(np.searchsorted(points, values), len(points) - 1)
    return np.asarray(points)[at] == values
