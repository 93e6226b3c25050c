"""Joint paths through waypoints: a C2 cubic spline, and straight segments with a stop at each
interior waypoint.

Both put the waypoints at s values proportional to the cumulative joint-space chord length, so s
runs at a uniform joint-space speed on average. Rest at both ends is the timing's job (path speed
sd = 0 there); keeping dq/ds != 0 at the ends keeps the phase plane regular there and lets a
motion start or end at a velocity tangent to the path. Continuous joints are interpolated as given
(no wrap-around to the short way).
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from planners.errors import InvalidRequest
from planners.paths.base import GeometricPath, PathPoints


def chord_knots(waypoints: np.ndarray) -> np.ndarray:
    """s of each waypoint, shape (n_waypoints,): cumulative Euclidean joint distance over its total.

    Raises:
        InvalidRequest: two consecutive waypoints coincide (the path would have no tangent there).
    """
    lengths = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    if np.any(lengths <= 1e-12):
        index = int(np.flatnonzero(lengths <= 1e-12)[0])
        raise InvalidRequest(f"path.waypoints[{index}] and path.waypoints[{index + 1}] coincide")
    cumulative = np.concatenate(([0.0], np.cumsum(lengths)))
    knots = cumulative / cumulative[-1]
    knots[-1] = 1.0
    return knots


class _ThroughWaypoints(GeometricPath):
    """A path that passes its waypoints at chord-length values of s (``knots``)."""

    def __init__(self, waypoints: np.ndarray):
        self.waypoints = np.asarray(waypoints, dtype=float)
        self.dof = self.waypoints.shape[1]
        self.knots = chord_knots(self.waypoints)


class SplinePath(_ThroughWaypoints):
    """C2 cubic spline through the waypoints, natural ends (d2q/ds2 = 0): two waypoints give the
    straight joint line at uniform speed in s.

    Args:
        waypoints: Shape (n_waypoints, n_dof), n_waypoints >= 2, in joint units.
    """

    def __init__(self, waypoints: np.ndarray):
        super().__init__(waypoints)
        self.kinks = np.empty(0)
        # Power-basis coefficients per knot interval, shape (4, n_waypoints - 1, n_dof):
        # q = c0 h^3 + c1 h^2 + c2 h + c3 with h = s - knot.
        self._coefficients = CubicSpline(self.knots, self.waypoints, axis=0, bc_type="natural").c

    def _local(self, s: np.ndarray):
        """The coefficients of the interval holding each s, and h = s - its knot, as (n, 1)."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        interval = np.clip(np.searchsorted(self.knots, s, side="right") - 1, 0, len(self.knots) - 2)
        c0, c1, c2, c3 = self._coefficients[:, interval]
        return c0, c1, c2, c3, (s - self.knots[interval])[:, None]

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        c0, c1, c2, c3, h = self._local(s)
        return PathPoints(((c0 * h + c1) * h + c2) * h + c3, (3.0 * c0 * h + 2.0 * c1) * h + c2, 6.0 * c0 * h + 2.0 * c1)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        c0, _, _, _, h = self._local(s)
        return np.broadcast_to(6.0 * c0, (len(h), self.dof)).copy()


class StopAndGoPath(_ThroughWaypoints):
    """Straight joint-space segments between waypoints, the motion stopping at each of them.

    Segment k runs over s in [s_k, s_k+1] as q = w_k + (w_k+1 - w_k) (s - s_k) / (s_k+1 - s_k).
    dq/ds jumps at every interior waypoint (``kinks``), so the path speed must vanish there.

    Args:
        waypoints: Shape (n_waypoints, n_dof), n_waypoints >= 2, in joint units.
    """

    def __init__(self, waypoints: np.ndarray):
        super().__init__(waypoints)
        self.kinks = self.knots[1:-1].copy()
        self._slopes = np.diff(self.waypoints, axis=0) / np.diff(self.knots)[:, None]

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        segment = np.searchsorted(self.knots, s, side="left" if side == "left" else "right") - 1
        segment = np.clip(segment, 0, len(self._slopes) - 1)
        slope = self._slopes[segment]
        q = self.waypoints[segment] + slope * (s - self.knots[segment])[:, None]
        return PathPoints(q, slope, np.zeros_like(slope))

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        return np.zeros((np.size(s), self.dof))
