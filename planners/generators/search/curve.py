"""The curve of a grid path: the uniform cubic B-spline whose control points are the grid points
(Jeong & Lee section 2.6 optimizes the control points of cubic B-splines; a grid path is the
first such curve). Before the first and after the last grid point a control point is added by
reflection (2 x_0 - x_1, 2 x_L - x_L-1), so the curve starts at the start and ends at the goal,
straight there (zero curvature), with the direction of the first and last edges.

The curve has one span per edge, parameter u in [span, span + 1] for span k between the points
(x_k-1 + 4 x_k + x_k+1) / 6 and (x_k + 4 x_k+1 + x_k+2) / 6 (the reflected points at the ends),
and s = u / L for L edges. It is C2 everywhere: no corner where the motion must stop, no jump of
curvature. Span k depends on the control points k - 1 ... k + 2 only, that is on three
consecutive moves of the grid path, which is what lets the search bound a partial path
(``toptraj.planners.generators.search.pieces``).
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.paths.base import GeometricPath, PathPoints

#: B(t) = sum_j (row_0 + row_1 t + row_2 t^2 + row_3 t^3)_j P_j over the span's four control
#: points: rows are the powers of t, columns the control points.
BASIS = np.array([[1.0, 4.0, 1.0, 0.0], [-3.0, 0.0, 3.0, 0.0], [3.0, -6.0, 3.0, 0.0], [-1.0, 3.0, -3.0, 1.0]]) / 6.0


def span_values(control: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, dq/dt and d2q/dt2 of spans with control points ``control`` (K, 4, n) at the local
    parameters ``t`` (m,) in [0, 1]: each of shape (K, m, n)."""
    coefficients = np.einsum("pj,kjn->kpn", BASIS, control)  # (K, 4 powers, n)
    t = np.asarray(t, dtype=float)
    powers = np.stack([np.ones_like(t), t, t**2, t**3])  # (4, m)
    slopes = np.stack([np.zeros_like(t), np.ones_like(t), 2 * t, 3 * t**2])
    bends = np.stack([np.zeros_like(t), np.zeros_like(t), 2 * np.ones_like(t), 6 * t])
    return (
        np.einsum("kpn,pm->kmn", coefficients, powers),
        np.einsum("kpn,pm->kmn", coefficients, slopes),
        np.einsum("kpn,pm->kmn", coefficients, bends),
    )


def control_points(points: np.ndarray) -> np.ndarray:
    """The grid points (k, n) with the reflected control points added at both ends (k + 2, n)."""
    points = np.asarray(points, dtype=float)
    return np.vstack([2.0 * points[0] - points[1], points, 2.0 * points[-1] - points[-2]])


class GridSplinePath(GeometricPath):
    """The uniform cubic B-spline through the control points of a grid path (see the module
    docstring).

    Args:
        points: The grid path's points, shape (L + 1, n_dof), L >= 1, no two consecutive ones
            equal (joint units).

    Attributes:
        points: The grid points (the curve's control points besides the reflected ends).
        spans: L, the number of spans (edges).
    """

    def __init__(self, points: np.ndarray):
        self.points = np.asarray(points, dtype=float)
        self.spans = len(self.points) - 1
        self.dof = self.points.shape[1]
        control = control_points(self.points)
        index = np.arange(self.spans)[:, None] + np.arange(4)[None, :]
        self._coefficients = np.einsum("pj,kjn->kpn", BASIS, control[index])  # (L, 4, n)
        self.knots = np.linspace(0.0, 1.0, self.spans + 1)
        self.kinks = np.empty(0)
        self.breaks = np.empty(0)

    def _locate(self, s):
        u = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, 1.0) * self.spans
        span = np.clip(np.floor(u).astype(int), 0, self.spans - 1)
        return span, (u - span)[:, None]

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        span, t = self._locate(s)
        c = self._coefficients[span]
        q = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
        dq = c[:, 1] + t * (2.0 * c[:, 2] + 3.0 * t * c[:, 3])
        ddq = 2.0 * c[:, 2] + 6.0 * t * c[:, 3]
        return PathPoints(q, dq * self.spans, ddq * self.spans**2)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        span, t = self._locate(s)
        return np.broadcast_to(6.0 * self._coefficients[span][:, 3], (len(t), self.dof)) * self.spans**3
