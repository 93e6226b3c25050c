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

from toptraj.compiled import njit
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.paths.base import RANGE_SLACK, GeometricPath, PathPoints

#: Joint-space distance (rad or m) at or below which two consecutive waypoints coincide: the path
#: would have no tangent between them. Two waypoints one of whose joint values differ by more are
#: apart (their Euclidean distance is then larger too).
COINCIDENT = 1e-12


def chord_knots(waypoints: np.ndarray) -> np.ndarray:
    """s of each waypoint, shape (n_waypoints,): cumulative Euclidean joint distance over its total.

    Raises:
        InvalidRequest: two consecutive waypoints coincide (the path would have no tangent there).
    """
    lengths = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    if np.any(lengths <= COINCIDENT):
        index = int(np.flatnonzero(lengths <= COINCIDENT)[0])
        raise InvalidRequest(f"waypoints[{index}]", waypoints[index], rule="waypoints_coincide", index=index, tolerance=COINCIDENT)
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
        self._coefficients = natural_spline_coefficients(self.knots, self.waypoints)

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        s = np.minimum(np.maximum(np.asarray(s, dtype=float).ravel(), 0.0), 1.0)
        return PathPoints(*cubic_pieces(self.knots, self._coefficients, s))

    def outside_range(self, lower: np.ndarray, upper: np.ndarray, samples: int) -> tuple[float, int, float] | None:
        """(s, joint, q) where the spline lies farthest beyond [``lower``, ``upper``], exactly
        (``cubic_farthest_outside``; ``samples`` is not needed), or ``None`` within them."""
        at, joint, value = cubic_farthest_outside(
            self.knots, self._coefficients, np.asarray(lower, dtype=float), np.asarray(upper, dtype=float), RANGE_SLACK
        )
        return None if joint < 0 else (at, joint, value)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        """d3q/ds3 (constant per piece; at a knot, the piece on ``side``)."""
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        interval = np.clip(np.searchsorted(self.knots, s, side="left" if side == "left" else "right") - 1, 0, len(self.knots) - 2)
        return 6.0 * self._coefficients[0, interval]


@njit(cache=True, nogil=True)
def natural_spline_coefficients(knots, values) -> np.ndarray:  # pragma: no cover - compiled
    """Power-basis coefficients (4, n_knots - 1, n_dof) of the C2 cubic spline through
    ``values`` (n_knots, n_dof) at ``knots`` (n_knots,) with natural ends (d2q/ds2 = 0).

    The second derivatives m_i at the knots solve the tridiagonal system (de Boor, *A Practical
    Guide to Splines*, ch. IV; h_i = knots[i+1] - knots[i], d_i = (values[i+1] - values[i]) / h_i)

        h_i-1 m_i-1 + 2 (h_i-1 + h_i) m_i + h_i m_i+1 = 6 (d_i - d_i-1),   m_0 = m_n = 0,

    strictly diagonally dominant, so elimination without pivoting (Thomas) is stable; then on
    piece i, with h = s - knots[i], q = c0 h^3 + c1 h^2 + c2 h + c3 where c0 = (m_i+1 - m_i) /
    (6 h_i), c1 = m_i / 2, c2 = d_i - h_i (2 m_i + m_i+1) / 6, c3 = values[i].
    """
    n_pieces, n_dof = knots.shape[0] - 1, values.shape[1]
    h = np.empty(n_pieces)
    slope = np.empty((n_pieces, n_dof))
    for i in range(n_pieces):
        h[i] = knots[i + 1] - knots[i]
        for j in range(n_dof):
            slope[i, j] = (values[i + 1, j] - values[i, j]) / h[i]
    m = np.zeros((n_pieces + 1, n_dof))
    inner = n_pieces - 1
    if inner > 0:
        diagonal = np.empty(inner)
        rhs = np.empty((inner, n_dof))
        for k in range(inner):  # unknown k is m_(k+1)
            diagonal[k] = 2.0 * (h[k] + h[k + 1])
            for j in range(n_dof):
                rhs[k, j] = 6.0 * (slope[k + 1, j] - slope[k, j])
        for k in range(1, inner):  # forward elimination; the sub- and superdiagonal entry is h[k]
            factor = h[k] / diagonal[k - 1]
            diagonal[k] -= factor * h[k]
            for j in range(n_dof):
                rhs[k, j] -= factor * rhs[k - 1, j]
        for j in range(n_dof):
            m[inner, j] = rhs[inner - 1, j] / diagonal[inner - 1]
        for k in range(inner - 2, -1, -1):
            for j in range(n_dof):
                m[k + 1, j] = (rhs[k, j] - h[k + 1] * m[k + 2, j]) / diagonal[k]
    coefficients = np.empty((4, n_pieces, n_dof))
    for i in range(n_pieces):
        for j in range(n_dof):
            coefficients[0, i, j] = (m[i + 1, j] - m[i, j]) / (6.0 * h[i])
            coefficients[1, i, j] = 0.5 * m[i, j]
            coefficients[2, i, j] = slope[i, j] - h[i] * (2.0 * m[i, j] + m[i + 1, j]) / 6.0
            coefficients[3, i, j] = values[i, j]
    return coefficients


@njit(cache=True, nogil=True)
def cubic_pieces(knots, coefficients, s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """q, dq/ds and d2q/ds2 (each (n, n_dof)) at ``s`` (n,) of the piecewise cubic with
    power-basis ``coefficients`` (4, n_knots - 1, n_dof) on ``knots``, in one pass (Horner);
    a knot belongs to the piece that starts there."""
    n, n_dof, last = s.shape[0], coefficients.shape[2], knots.shape[0] - 2
    q = np.empty((n, n_dof))
    dq = np.empty((n, n_dof))
    ddq = np.empty((n, n_dof))
    piece = 0
    for i in range(n):
        # The piece holding s[i]: stepped on from the last one while s increases (the usual
        # order), searched for where it does not.
        at = s[i]
        if at < knots[piece] or (piece < last and at >= knots[piece + 1]):
            piece = min(max(np.searchsorted(knots, at, side="right") - 1, 0), last)
        h = at - knots[piece]
        for j in range(n_dof):
            c0 = coefficients[0, piece, j]
            c1 = coefficients[1, piece, j]
            c2 = coefficients[2, piece, j]
            q[i, j] = ((c0 * h + c1) * h + c2) * h + coefficients[3, piece, j]
            dq[i, j] = (3.0 * c0 * h + 2.0 * c1) * h + c2
            ddq[i, j] = 6.0 * c0 * h + 2.0 * c1
    return q, dq, ddq


@njit(cache=True, nogil=True)
def cubic_farthest_outside(knots, coefficients, lower, upper, slack) -> tuple[float, int, float]:  # pragma: no cover - compiled
    """(s, joint, q) where the piecewise cubic (power-basis ``coefficients`` (4, n_knots - 1,
    n_dof) on ``knots``) lies farthest beyond [``lower``, ``upper``] (n_dof,), by more than
    ``slack``; joint -1 where it stays within. Each piece's extremes lie at its ends or where
    dq/ds = 3 c0 h^2 + 2 c1 h + c2 vanishes inside it (the roots taken without cancellation,
    Press et al., *Numerical Recipes*, section 5.6)."""
    best, at, joint, value = slack, 0.0, -1, 0.0
    candidates = np.empty(4)
    for piece in range(knots.shape[0] - 1):
        length = knots[piece + 1] - knots[piece]
        for j in range(coefficients.shape[2]):
            c0, c1, c2, c3 = coefficients[0, piece, j], coefficients[1, piece, j], coefficients[2, piece, j], coefficients[3, piece, j]
            candidates[0], candidates[1] = 0.0, length
            count = 2
            a, b = 3.0 * c0, 2.0 * c1
            if a != 0.0:
                discriminant = b * b - 4.0 * a * c2
                if discriminant >= 0.0:
                    half = -0.5 * (b + np.copysign(np.sqrt(discriminant), b))
                    candidates[count] = half / a
                    count += 1
                    if half != 0.0:
                        candidates[count] = c2 / half
                        count += 1
            elif b != 0.0:
                candidates[count] = -c2 / b
                count += 1
            for k in range(count):
                h = candidates[k]
                if not 0.0 <= h <= length:
                    continue
                q = ((c0 * h + c1) * h + c2) * h + c3
                excess = max(q - upper[j], lower[j] - q)
                if excess > best:
                    best, at, joint, value = excess, knots[piece] + h, j, q
    return at, joint, value


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
