"""A clamped cubic B-spline in joint space: the path shape of the local optimization (Jeong &
Lee §2.6, after Shiller & Dubowsky), whose control points are the variables.

With the knot vector clamped (the first and last knots repeated four times), q(0) and q(1) are
the first and last control points, dq/ds at the ends points along the first and last legs of
the control polygon, and the curve lies within the convex hull of its control points. Inserting
a knot (Boehm) adds a control point and leaves the curve unchanged, so the spaces of curves
on successively refined knot vectors are nested.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.errors import InvalidRequest
from toptraj.planners.paths.base import GeometricPath, PathPoints
from toptraj.planners.paths.waypoints import cubic_pieces

DEGREE = 3


def clamped_knots(interior: np.ndarray) -> np.ndarray:
    """The full knot vector (len(interior) + 8,) of a clamped cubic on [0, 1] with the given
    increasing ``interior`` knots (each strictly inside (0, 1))."""
    interior = np.asarray(interior, dtype=float).ravel()
    return np.concatenate([np.zeros(DEGREE + 1), interior, np.ones(DEGREE + 1)])


def insert_knot(knots: np.ndarray, control: np.ndarray, at: float) -> tuple[np.ndarray, np.ndarray]:
    """Boehm's knot insertion: the knot vector and control points (k + 1, n_dof) of the same
    curve with the knot ``at`` (strictly inside (0, 1)) added."""
    # the interval [t_i, t_i+1) holding ``at``
    i = int(np.searchsorted(knots, at, side="right") - 1)
    new = np.empty((len(control) + 1, control.shape[1]))
    new[: i - DEGREE + 1] = control[: i - DEGREE + 1]
    for j in range(i - DEGREE + 1, i + 1):
        alpha = (at - knots[j]) / (knots[j + DEGREE] - knots[j])
        new[j] = (1.0 - alpha) * control[j - 1] + alpha * control[j]
    new[i + 1 :] = control[i:]
    return np.insert(knots, i + 1, at), new


class BSplinePath(GeometricPath):
    """q(s) = sum_i N_i(s) P_i, s in [0, 1], a clamped cubic B-spline: C2 everywhere.

    Args:
        control: Control points P, shape (k, n_dof), k >= 4, in joint units; P_0 is the start
            and P_k-1 the goal.
        interior: Interior knots, increasing, strictly inside (0, 1), k - 4 of them; ``None``:
            uniform.

    Attributes:
        knots: 0, the distinct interior knots and 1 (where d3q/ds3 jumps).
    """

    def __init__(self, control: np.ndarray, interior: np.ndarray | None = None):
        control = np.asarray(control, dtype=float)
        if control.ndim != 2 or len(control) < DEGREE + 1:
            raise InvalidRequest(
                "control", control.shape, rule="bspline_control_points",
                detail=f"a cubic B-spline needs at least 4 control points of shape (k, n_dof); got shape {control.shape}",
            )
        if interior is None:
            interior = np.linspace(0.0, 1.0, len(control) - DEGREE + 1)[1:-1]
        interior = np.asarray(interior, dtype=float).ravel()
        if len(interior) != len(control) - DEGREE - 1 or np.any(np.diff(interior) <= 0.0) or (
            interior.size and (interior[0] <= 0.0 or interior[-1] >= 1.0)
        ):
            raise InvalidRequest(
                "interior", interior, rule="bspline_knots",
                detail=f"a clamped cubic B-spline with {len(control)} control points needs {len(control) - DEGREE - 1} "
                "increasing interior knots inside (0, 1)",
            )
        self.control = control
        self.interior = interior
        self.dof = control.shape[1]
        self.knots = np.concatenate([[0.0], interior, [1.0]])
        self.kinks = np.empty(0)
        self.breaks = np.empty(0)
        from scipy.interpolate import BSpline  # here: the searches' paths only, not every request

        self._spline = BSpline(clamped_knots(interior), control, DEGREE)
        # Power-basis coefficients per knot interval, (4, pieces, n_dof), for ``cubic_pieces``.
        left = self.knots[:-1]
        derivatives = [self._spline(left, nu) for nu in range(DEGREE + 1)]
        self._coefficients = np.ascontiguousarray(
            np.stack([derivatives[3] / 6.0, derivatives[2] / 2.0, derivatives[1], derivatives[0]])
        )

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        return PathPoints(*cubic_pieces(self.knots, self._coefficients, s))

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        """d3q/ds3 (constant per knot interval; at a knot, the interval on ``side``)."""
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        piece = np.searchsorted(self.knots, s, side="left" if side == "left" else "right") - 1
        return 6.0 * self._coefficients[0, np.clip(piece, 0, len(self.knots) - 2)]
