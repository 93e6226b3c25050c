"""The linear program of one conservative restriction of the jerk-limited timing
(``toptraj.planners.timing.jerk.method``, after Lee, Bylard, Sun & Sentis, arXiv 2404.07889): every
limit linear in (x, u) = (sd^2, sdd), the jerk limit's right-hand side J / sqrt(x) replaced by
its tangent at the current solution, solved by HiGHS's dual simplex over a working set of its
rows (``toptraj.planners.timing.jerk.working_set``).

Discretization (``JerkTimeScaling``): x and u at the grid points, u linear in s between them
(x_i+1 = x_i + (u_i + u_i+1) h_i), the jerk rows (``toptraj.planners.timing.jerk.method``'s (1), its
right-hand side the tangent) at both ends of every interval with du/ds = (u_i+1 - u_i) / h_i,
the second-order rows at every grid point and at the middle of
every interval (where x = x_i + (3 u_i + u_i+1) h_i / 4), the velocity bound at its quarters
too (without them u may zigzag along a stretch of constant x). An interval that starts (ends)
at rest holds the motion of constant path jerk from (to) rest, u = 2 x / (3 s),
du/ds = 2 x / (9 s^2), which the linear-u interval cannot represent (it would never leave
rest); the grid gets points around the end of that phase, as long as the limits at rest make
it. The objective, the duration, is linearized at the current solution. Variables are scaled by a
typical x, so that the LP sees numbers of order one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import Boundary
from toptraj.planners.timing.jerk.scaling import JerkTimeScaling, interval_times
from toptraj.planners.timing.jerk.tangent_rows import TangentRows

if TYPE_CHECKING:
    from scipy import sparse


class RestrictedProgram:
    """The LP of one restriction, in the scaled variables X = x / kappa, U = u / kappa (kappa a
    typical x, so that the LP sees numbers of order one)."""

    def __init__(self, constraints: PathConstraints, boundary: Boundary, x_ref: np.ndarray, deadline: Deadline = NO_DEADLINE):
        self.constraints = constraints
        self.deadline = deadline
        s = constraints.s
        self.n = n = len(s) - 1
        self.h = np.diff(s)
        positive = x_ref[x_ref > 0]
        self.kappa = float(np.median(positive)) if positive.size else 1.0
        self.x_start, self.x_end = boundary.sd_start**2, boundary.sd_end**2
        self.rest_start, self.rest_end = self.x_start == 0.0, self.x_end == 0.0
        if n < 2 + self.rest_start + self.rest_end:
            raise TimingFailed("the grid is too coarse for the jerk-limited timing")
        self._fixed_rows = self._equalities_and_rows(x_ref)
        # here: scipy.sparse is imported by jerk_limited only
        from toptraj.planners.timing.jerk.working_set import WorkingSetLP

        self._lp = WorkingSetLP(deadline)
        self._fixed: tuple[sparse.csr_matrix, np.ndarray, np.ndarray] | None = None
        self._tangent: TangentRows | None = None
        self._lower = np.zeros(0)

    # Variables: X_0..X_n at columns 0..n, U_0..U_n at columns n+1..2n+1.
    def _x(self, i):
        """Column of X_i."""
        return np.asarray(i)

    def _u(self, i):
        """Column of U_i."""
        return np.asarray(i) + self.n + 1

    def _equalities_and_rows(self, x_ref):
        """Continuity of x, the intervals at rest, and the second-order rows (which do not
        depend on the restriction, except through friction linearized at ``x_ref``): blocks of
        ``_stacked``."""
        regular = np.arange(1 if self.rest_start else 0, self.n - 1 if self.rest_end else self.n)
        right = self.constraints.linearized(np.maximum(x_ref, 1e-12))
        left = self.constraints.linearized(np.maximum(x_ref, 1e-12), "left")
        return [
            self._continuity(),
            *self._quarter_speed_rows(regular),
            *self._point_rows(right, left),
            *self._middle_rows(right, left, regular),
        ]

    def _continuity(self):
        """x_i+1 = x_i + (u_i + u_i+1) h_i on every regular interval; u = 2 x / (3 h) at the
        inner point of an interval at rest (constant path jerk from or to rest)."""
        n, h = self.n, self.h
        interval = np.arange(n)
        columns = np.column_stack([self._x(interval + 1), self._x(interval), self._u(interval), self._u(interval + 1)])
        values = np.column_stack([np.ones(n), -np.ones(n), -h, -h])
        width = np.full(n, 4)
        if self.rest_start:
            columns[0, :2], values[0, :2], width[0] = (self._u(1), self._x(1)), (1.0, -2.0 / (3.0 * h[0])), 2
        if self.rest_end:
            columns[-1, :2], values[-1, :2], width[-1] = (self._u(n - 1), self._x(n - 1)), (1.0, 2.0 / (3.0 * h[-1])), 2
        used = np.arange(4)[None, :] < width[:, None]
        return (
            np.repeat(interval, width), columns[used], values[used], np.zeros(n), np.zeros(n), n,
        )

    def _quarter_speed_rows(self, regular: np.ndarray):
        """x at the quarters of each regular interval, x_i + 2 u_i f h + (u_i+1 - u_i) f^2 h
        (f = 1/4, 1/2, 3/4), below the velocity bound of both ends: without them, u could
        zigzag (u_i+1 = -u_i) along a stretch of constant x, its x bulging between the grid
        points."""
        x_bound = self.constraints.sd_max**2 / self.kappa
        bound = np.minimum(x_bound[regular], x_bound[regular + 1])
        keep = np.isfinite(bound)
        bounded, bound = regular[keep], bound[keep]
        if bounded.size == 0:
            return []
        hb = self.h[bounded]
        return [
            (
                np.repeat(np.arange(bounded.size), 3),
                np.column_stack([self._x(bounded), self._u(bounded), self._u(bounded + 1)]).ravel(),
                np.column_stack([np.ones(bounded.size), (2.0 * f - f * f) * hb, f * f * hb]).ravel(),
                np.full(bounded.size, -np.inf),
                bound,
                bounded.size,
            )
            for f in (0.25, 0.5, 0.75)
        ]

    def _point_rows(self, right, left):
        """The second-order rows a u + b x + c within [lower, upper] at every inner grid point,
        with the coefficients of both sides where the path's derivatives jump there."""
        kappa, free = self.kappa, np.arange(1, self.n)
        differs = np.flatnonzero(
            np.any(left.a != right.a, axis=1) | np.any(left.b != right.b, axis=1) | np.any(left.c != right.c, axis=1)
        )
        blocks = []
        for side, points in ((right, free), (left, np.intersect1d(differs, free))):
            if side.a.shape[1] == 0 or points.size == 0:
                continue
            a, b, cc = side.a[points], side.b[points], side.c[points]
            lo, hi = side.lower[points] - cc, side.upper[points] - cc
            scale = np.maximum(np.maximum(np.abs(a), np.abs(b)) * kappa, 1e-300)
            m = a.shape[1]
            point_index = np.repeat(points, m)
            blocks.append((
                np.repeat(np.arange(points.size * m), 2),
                np.column_stack([self._u(point_index), self._x(point_index)]).ravel(),
                np.column_stack([(a * kappa / scale).ravel(), (b * kappa / scale).ravel()]).ravel(),
                (lo / scale).ravel(),
                (hi / scale).ravel(),
                points.size * m,
            ))
        return blocks

    def _middle_rows(self, right, left, regular: np.ndarray):
        """The second-order rows at the middle of each regular interval, where
        u = (u_i + u_i+1) / 2 and x = x_i + (3 u_i + u_i+1) h / 4 (x is quadratic in s between
        the grid points), with the coefficients of the two ends averaged."""
        if not (right.a.shape[1] and regular.size):
            return []
        i = regular
        a = 0.5 * (right.a[i] + left.a[i + 1])
        b = 0.5 * (right.b[i] + left.b[i + 1])
        cc = 0.5 * (right.c[i] + left.c[i + 1])
        lo, hi = right.lower[i] - cc, right.upper[i] - cc
        hm = self.h[i][:, None]
        coefficients = np.stack([0.5 * a + 0.75 * hm * b, 0.5 * a + 0.25 * hm * b, b], axis=-1) * self.kappa
        scale = np.maximum(np.abs(coefficients).max(axis=-1), 1e-300)
        m = a.shape[1]
        index = np.repeat(i, m)
        return [(
            np.repeat(np.arange(i.size * m), 3),
            np.column_stack([self._u(index), self._u(index + 1), self._x(index)]).ravel(),
            (coefficients / scale[..., None]).reshape(-1),
            (lo / scale).ravel(),
            (hi / scale).ravel(),
            i.size * m,
        )]

    def _tangent_rows(self) -> TangentRows:
        """The jerk rows (1) at both ends of every interval, their right-hand side J / sqrt(X)
        replaced by its tangent (``toptraj.planners.timing.jerk.tangent_rows``): G's
        coefficients do not depend on the tangent, and are gathered once per grid."""
        if self._tangent is None:
            limit = self._jerk[3]
            limited = np.flatnonzero(np.isfinite(limit))
            terms = (*self._regular_jerk_terms(limited), *self._rest_jerk_terms(limited)) if limited.size else ()
            J = limit[limited] / self.kappa**1.5  # scaled: |G| <= J / sqrt(X)
            assert self._fixed is not None
            self._tangent = TangentRows(terms, J, self._x, self._fixed[0], 2 * self.n + 2)
        return self._tangent

    @property
    def _jerk(self):
        """The path's jerk coefficients (q', q'', q''', J) on the right of each point."""
        assert self.constraints.jerk is not None  # jerk_limited always builds the jerk rows
        return self.constraints.jerk

    @property
    def _jerk_left(self):
        """The path's jerk coefficients (q', q'', q''') on the left of each point."""
        assert self.constraints.jerk_left is not None  # built with the jerk rows
        return self.constraints.jerk_left

    def _regular_jerk_terms(self, limited: np.ndarray):
        """(u terms, X coefficient, points) of G = d1 (U_i+1 - U_i) / h_i + 3 d2 U_p + d3 X_p
        at both ends p of every regular interval i, the points at rest left out."""
        n, h = self.n, self.h
        regular = np.arange(1 if self.rest_start else 0, n - 1 if self.rest_end else n)
        terms = []
        for end, (d1, d2, d3) in ((0, self._jerk[:3]), (1, self._jerk_left)):
            point = regular + end
            moving = ~(((point == 0) & self.rest_start) | ((point == n) & self.rest_end))
            point = point[moving]
            if point.size == 0:
                continue
            interval = point - end
            hw = h[interval][:, None]
            a1, a2, a3 = d1[point][:, limited], d2[point][:, limited], d3[point][:, limited]
            u_terms = [(self._u(interval + 1), a1 / hw), (self._u(interval), -a1 / hw), (self._u(point), 3.0 * a2)]
            terms.append((u_terms, a3, point))
        return terms

    def _rest_jerk_terms(self, limited: np.ndarray):
        """(u terms, X coefficient, points) of the jerk of an interval at rest, at its inner
        point, where u = sign 2 x / (3 h) and du/ds = 2 x / (9 h^2):
        G = X (d1 2 / (9 h^2) + sign 2 d2 / h + d3); and at the rest point, where the jerk is
        q' sigma, sigma = du/ds sqrt(x): G = X d1 2 / (9 h^2)."""
        dq, ddq, dddq, _ = self._jerk
        terms: list = []
        for at_rest, inner, outer, sign in ((self.rest_start, 1, 0, 1.0), (self.rest_end, self.n - 1, self.n, -1.0)):
            if not at_rest:
                continue
            width = self.h[0] if outer == 0 else self.h[-1]
            d1, d2, d3 = self._jerk_left if outer == 0 else (dq, ddq, dddq)
            point = np.array([inner])
            inner_g = d1[inner] * 2.0 / (9.0 * width**2) + sign * d2[inner] * 2.0 / width + d3[inner]
            outer_g = dq[outer] * 2.0 / (9.0 * width**2)
            terms.extend(([], g[limited][None, :], point) for g in (inner_g, outer_g))
        return terms

    def solve_restricted(self, x_tangent: np.ndarray, seed: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The LP of the restriction around ``x_tangent`` (1/s^2): x and u (unscaled). ``seed``,
        x and u near the optimum (unscaled), chooses the rows the first LP starts with
        (``toptraj.planners.timing.jerk.working_set``)."""
        kappa, n = self.kappa, self.n
        X_tangent = np.asarray(x_tangent) / kappa
        matrix, lower, upper = self._rows(X_tangent)
        x_high = self.constraints.sd_max**2 / kappa
        low = np.concatenate([np.zeros(n + 1), np.full(n + 1, -np.inf)])
        high = np.concatenate([x_high, np.full(n + 1, np.inf)])
        for index, value in ((self._x(0), self.x_start / kappa), (self._x(n), self.x_end / kappa), (self._u(0), 0.0), (self._u(n), 0.0)):
            low[index] = high[index] = value
        objective = np.zeros(2 * n + 2)
        objective[: n + 1] = self._time_gradient(np.maximum(X_tangent, 1e-12))
        scaled = None if seed is None else np.concatenate(seed) / kappa
        values = self._lp.solve(objective, matrix, lower, upper, low, high, scaled)
        X, U = values[: n + 1], values[n + 1 :]
        return np.maximum(X, 0.0) * kappa, U * kappa

    def _rows(self, X_tangent: np.ndarray) -> tuple[sparse.csr_matrix, np.ndarray, np.ndarray]:
        """Every row of the LP around ``X_tangent``: (matrix (CSR), lower, upper), the rows that
        do not depend on the restriction first: the pattern is built at the first restriction,
        a later one computes the jerk rows' values only (``TangentRows.values``)."""
        from scipy import sparse

        columns = 2 * self.n + 2
        if self._fixed is None:  # the rows that do not depend on the restriction, built once
            self._fixed = _stacked(self._fixed_rows, columns)
        fixed, fixed_lower, fixed_upper = self._fixed
        tangent = self._tangent_rows()
        values, jerk_upper = tangent.values(X_tangent)
        if self._lower.size == 0:
            self._lower = np.concatenate([fixed_lower, np.full(tangent.offset, -np.inf)])
        data = np.concatenate([fixed.data, values])
        matrix = sparse.csr_matrix((data, tangent.indices, tangent.indptr), shape=(tangent.rows, columns))
        return matrix, self._lower, np.concatenate([fixed_upper, jerk_upper])

    def _time_gradient(self, X):
        """d/dX of sum 2 h / (sqrt(X_i) + sqrt(X_i+1)) (3 h / sqrt(X) for an interval at rest)."""
        root = np.sqrt(X)
        gradient = np.zeros_like(X)
        share = -self.h / (root[:-1] + root[1:]) ** 2
        gradient[:-1] += share / root[:-1]
        gradient[1:] += share / root[1:]
        if self.rest_start:
            gradient[0] = 0.0
            gradient[1] += -1.5 * self.h[0] / X[1] ** 1.5 - share[0] / root[1]
        if self.rest_end:
            gradient[-1] = 0.0
            gradient[-2] += -1.5 * self.h[-1] / X[-2] ** 1.5 - share[-1] / root[-2]
        return gradient

    def durations(self, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Durations (M,) in s of the motions x, u (M, N + 1) on this grid."""
        return interval_times(self.constraints.s, np.maximum(x, 0.0), u, self.rest_start, self.rest_end).sum(axis=1)

    def timing(self, x: np.ndarray, u: np.ndarray) -> JerkTimeScaling:
        return JerkTimeScaling(
            self.constraints.s, np.sqrt(np.maximum(x, 0.0)), u=np.asarray(u, dtype=float),
            rest_start=self.rest_start, rest_end=self.rest_end,
        )


def _stacked(blocks, columns: int) -> tuple[sparse.csr_matrix, np.ndarray, np.ndarray]:
    """The rows of ``blocks`` (row, column, value, lower, upper, count; rows numbered within each
    block) one under the other: the matrix (CSR, ``columns`` wide) and its bounds."""
    from scipy import sparse

    if not blocks:
        return sparse.csr_matrix((0, columns)), np.zeros(0), np.zeros(0)
    offsets = np.cumsum([0] + [block[5] for block in blocks])
    matrix = sparse.csr_matrix(
        (
            np.concatenate([block[2] for block in blocks]),
            (
                np.concatenate([block[0] + offset for block, offset in zip(blocks, offsets)]),
                np.concatenate([block[1] for block in blocks]),
            ),
        ),
        shape=(offsets[-1], columns),
    )
    return matrix, np.concatenate([block[3] for block in blocks]), np.concatenate([block[4] for block in blocks])
