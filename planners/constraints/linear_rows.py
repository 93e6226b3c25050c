"""Second-order path constraints as linear rows in the phase plane: ``a u + b x + c`` within
``[lower, upper]`` at each grid point (u = sdd, x = sd^2; Pham & Pham 2018, eq. (3)), and their
normalization for solvers with absolute tolerances."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LinearRows:
    """Second-order rows ``a u + b x + c in [lower, upper]``, each of shape (N + 1, m)."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    def normalized(self) -> LinearRows:
        """The same rows, each column divided by the largest magnitude over the grid of its
        coefficients a and b and its finite bounds (columns with none keep their scale):
        ``a u + b x + c in [lower, upper]`` holds exactly when the row divided by k > 0 does. A
        solver with absolute tolerances (toppra's LP, Clarabel; about 1e-8) then sees rows of
        order one whatever the limits: without it, it could not tell an acceleration limit of
        1e-6 rad/s^2 from zero. One factor per column: a factor per grid point made toppra's
        answer on a blended path 29 % slower; coefficients alone, without the bounds, failed
        limits 1e-6 and 1e5 apart on the joints of one arm. Only columns whose scale lies outside
        ``ROW_SCALES`` are divided: on rows of ordinary size the solvers' own conditioning is
        the better one (dividing every column made toppra fail on torque-limited paths of the
        Yamamoto arm that it solves as given)."""
        k = np.maximum.reduce([np.abs(self.a), np.abs(self.b), np.abs(self.lower), np.abs(self.upper)])
        k = np.where(np.isfinite(k), k, np.maximum(np.abs(self.a), np.abs(self.b)))
        k = np.where(np.isfinite(k), k, 0.0).max(axis=0, initial=0.0)
        low, high = ROW_SCALES
        k = np.where((k > 0.0) & ((k < low) | (k > high)), k, 1.0)
        return LinearRows(self.a / k, self.b / k, self.c / k, self.lower / k, self.upper / k)


#: Scales of a row's column (its largest coefficient or finite bound over the grid) that
#: ``LinearRows.normalized`` leaves as they are: within them, a solver's absolute tolerance
#: (about 1e-8) is small against the row.
ROW_SCALES = (1e-2, 1e4)
