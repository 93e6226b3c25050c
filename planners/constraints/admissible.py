"""The admissible set of the phase plane at each grid point: the interval of x = sd^2 for which
some path acceleration u satisfies every second-order row, capped by the first-order bound.
Its upper end is the maximum velocity curve (MVC), the "velocity limit curve" of Jeong & Lee
section 3.2 (the limit that the torque bounds (3.6) place on mu = lambda-dot).

Each row ``lower <= a u + b x + c <= upper`` with a != 0 bounds u between two functions linear
in x, l_k(x) <= u <= h_k(x). Some u exists iff l_i(x) <= h_j(x) for every pair (i, j): each pair
is one linear inequality in x, and rows with a = 0 bound x directly. The admissible x therefore
form one interval per grid point (``toptraj.planners.constraints.admissible_kernels.admissible_intervals``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.constraints.admissible_kernels import ZERO_INERTIA, point_bounds
from toptraj.planners.constraints.linear_rows import LinearRows

if TYPE_CHECKING:
    from toptraj.planners.constraints.path_constraints import PathConstraints


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


@dataclass(frozen=True)
class AccelerationBounds:
    """Each row with a != 0 as bounds on u linear in x: ``p + q x <= u <= r + w x``, each of
    shape (N + 1, m); ``-inf``/``inf`` intercepts mark a missing bound. ``singular`` marks rows
    with a = 0 (zero inertia), which bound x alone and are left out of p, q, r, w."""

    p: np.ndarray
    q: np.ndarray
    r: np.ndarray
    w: np.ndarray
    singular: np.ndarray


def acceleration_bounds(rows: LinearRows) -> AccelerationBounds:
    """Solve every row of ``rows`` for u (Jeong & Lee eq. (3.6) divided by its u-coefficient)."""
    a, b, c, lower, upper = rows.a, rows.b, rows.c, rows.lower, rows.upper
    scale = np.maximum(np.abs(a) + np.abs(b), 1e-300)
    singular = np.abs(a) <= ZERO_INERTIA * scale
    safe_a = np.where(singular, 1.0, a)
    with np.errstate(invalid="ignore", divide="ignore"):
        from_upper = (upper - c) / safe_a
        from_lower = (lower - c) / safe_a
        slope = np.where(singular, 0.0, -b / safe_a)
    positive = a > 0
    p = np.where(positive, from_lower, from_upper)
    r = np.where(positive, from_upper, from_lower)
    p = np.where(singular | np.isnan(p), -np.inf, p)
    r = np.where(singular | np.isnan(r), np.inf, r)
    return AccelerationBounds(p=p, q=slope, r=r, w=slope, singular=singular)


def admissible_set(rows: LinearRows, x_bound: np.ndarray) -> AdmissibleSet:
    """Admissible x at every grid point for ``rows`` and the first-order bound ``x <= x_bound``."""
    a, b, c, lower, upper = (
        np.ascontiguousarray(array, dtype=float) for array in (rows.a, rows.b, rows.c, rows.lower, rows.upper)
    )
    x_bound = np.ascontiguousarray(np.broadcast_to(np.asarray(x_bound, dtype=float), a.shape[:1]))
    p, q, r, x_low, x_high, singular, static_fail = point_bounds(a, b, c, lower, upper, x_bound)
    empty = x_high < 0.0
    blocking = np.full((len(x_low), 2), -1)
    if empty.any():
        bounds = AccelerationBounds(p=p, q=q, r=r, w=q, singular=singular)
        for point in np.flatnonzero(empty):
            blocking[point] = _blocking_pair(point, bounds, x_low, static_fail, singular, rows)
    return AdmissibleSet(x_min=x_low, x_max=x_high, blocking_rows=blocking)


def _blocking_pair(point, bounds, x_min, static_fail, singular, rows):
    """The two rows whose bounds on u conflict most at ``point`` (at the lowest admissible x)."""
    if static_fail[point]:
        failing = (rows.c[point] > rows.upper[point]) | (rows.c[point] < rows.lower[point])
        row = int(np.flatnonzero(singular[point] & failing)[0])
        return row, row
    x = max(x_min[point], 0.0)
    low = bounds.p[point] + bounds.q[point] * x
    high = bounds.r[point] + bounds.w[point] * x
    return int(np.argmax(low)), int(np.argmin(high))


def friction_reference(constraints: PathConstraints) -> np.ndarray:
    """A first guess of the optimal x = sd^2 (N + 1,) around which viscous friction is
    linearized (``PathConstraints.linearized``): the maximum velocity curve without friction,
    capped by the first-order bound; without friction, that bound itself (it is not used)."""
    x_bound = constraints.sd_max**2
    if not constraints.has_friction:
        return x_bound
    frictionless = LinearRows(constraints.a, constraints.b, constraints.c, constraints.lower, constraints.upper)
    x_max = admissible_set(frictionless, x_bound).x_max
    return np.where(np.isfinite(x_max) & (x_max > 0), x_max, 1.0)


def speed_scale(constraints: PathConstraints) -> float:
    """A typical x = sd^2 of the path (1/s^2), or 1 when the limits give none: the median over
    the grid of the smaller of the maximum velocity curve (without friction) and the largest
    path acceleration u available from rest, which bounds the x reachable over a stretch of
    unit length (x = 2 u s). Paths whose s runs over a tiny stretch of joint space have x of 1e6
    and more; dividing by this scale brings the numbers a solver sees to order one
    (``PathConstraints.time_scaled``)."""
    frictionless = LinearRows(constraints.a, constraints.b, constraints.c, constraints.lower, constraints.upper)
    x_max = admissible_set(frictionless, constraints.sd_max**2).x_max
    u_max = acceleration_bounds(frictionless).r.min(axis=1, initial=np.inf)
    typical = np.minimum(x_max, np.abs(u_max))
    usable = typical[np.isfinite(typical) & (typical > 0)]
    return float(np.median(usable)) if usable.size else 1.0
