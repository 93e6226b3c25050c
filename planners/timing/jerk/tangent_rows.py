"""The jerk rows of the jerk-limited timing's linear programs (``toptraj.planners.timing.jerk.program``),
their right-hand side J / sqrt(X) replaced by its tangent at the current solution (Lee, Bylard,
Sun & Sentis, arXiv 2404.07889; ``toptraj.planners.timing.jerk.method``'s (1)).

Each point p and limited joint gives two one-sided rows,

    +-G + J beta X_p <= J alpha,    alpha = 1.5 / sqrt(X_t),  beta = 0.5 / X_t^1.5,

G = sum of its U terms + g X_p (scaled variables), each row scaled to a largest coefficient of one.
Only alpha and beta depend on the tangent X_t: the rows' pattern, their U coefficients and the
largest of them are fixed for a grid, so that a new restriction recomputes one X coefficient,
one scale and one bound per row (``TangentRows.values``), in one pass over flat arrays.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy import sparse

#: One family of rows: (U terms, as (columns (k,), coefficients (k, m)) pairs; the X coefficient
#: g (k, m); the points (k,)), for k points and m limited joints.
Term = tuple[list, np.ndarray, np.ndarray]


class TangentRows:
    """The jerk rows of one grid, ``+G`` then ``-G`` for each family of ``terms`` in order, each
    family's rows point by point, joint by joint; their entries the U terms then X.

    Args:
        terms: The families (``Term``).
        J: The jerk limits of the limited joints (m,), scaled to the variables.
        x_column: The column of X_p, for the points p (array -> array).
        fixed: The rows that do not depend on the restriction (CSR, ``columns`` wide), which
            come first in the LP's matrix.
        columns: The LP's columns.
    """

    def __init__(
        self, terms: Sequence[Term], J: np.ndarray, x_column: Callable[[np.ndarray], np.ndarray], fixed: sparse.csr_matrix, columns: int,
    ):
        static, entry_row, entry_column, is_x = [], [], [], []
        self.offset, coefficient, largest, limit, point = 0, [], [], [], []
        for u_terms, x_coefficient, points in terms:
            k, m = x_coefficient.shape
            width = len(u_terms) + 1
            u = np.stack([c for _, c in u_terms], axis=-1) if u_terms else np.zeros((k, m, 0))
            cols = np.stack(
                [*(np.broadcast_to(c[:, None], (k, m)) for c, _ in u_terms), np.broadcast_to(x_column(points)[:, None], (k, m))],
                axis=-1,
            ).reshape(-1)
            x_entry = np.zeros((k, m, width), dtype=bool)
            x_entry[..., -1] = True
            for sign in (1.0, -1.0):
                static.append(np.concatenate([sign * u, np.zeros((k, m, 1))], axis=-1).reshape(-1))
                entry_row.append(self.offset + np.repeat(np.arange(k * m), width))
                entry_column.append(cols)
                is_x.append(x_entry.reshape(-1))
                coefficient.append((sign * x_coefficient).ravel())
                largest.append((np.abs(u).max(axis=-1) if u_terms else np.zeros((k, m))).ravel())
                limit.append(np.broadcast_to(J, (k, m)).ravel())
                point.append(np.repeat(points, m))
                self.offset += k * m
        flat = [np.concatenate(part) if part else np.zeros(0) for part in (static, coefficient, largest, limit)]
        self._static, self._coefficient, self._largest, self._limit = flat
        self._entry_row = np.concatenate(entry_row).astype(np.int64) if entry_row else np.zeros(0, dtype=np.int64)
        self._is_x = np.concatenate(is_x) if is_x else np.zeros(0, dtype=bool)
        self._point = np.concatenate(point).astype(np.int64) if point else np.zeros(0, dtype=np.int64)
        column = np.concatenate(entry_column).astype(np.int64) if entry_column else np.zeros(0, dtype=np.int64)
        self._pattern(fixed, column, columns)

    def _pattern(self, fixed: sparse.csr_matrix, column: np.ndarray, columns: int) -> None:
        """The whole matrix's ``indptr`` and ``indices`` (CSR, the fixed rows over these, rows
        sorted, repeated entries summed), and for each entry of these rows, in their order, the
        entry of the jerk part it adds to (``entry``, of ``nnz``)."""
        keys, self.entry = np.unique(self._entry_row * columns + column, return_inverse=True)
        self.nnz = keys.size
        counts = np.bincount(keys // columns, minlength=self.offset)
        self.rows = fixed.shape[0] + self.offset
        self.indptr = np.concatenate([fixed.indptr, fixed.indptr[-1] + np.cumsum(counts)]).astype(fixed.indptr.dtype)
        self.indices = np.concatenate([fixed.indices, keys % columns]).astype(fixed.indices.dtype)

    def values(self, X_tangent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The rows' matrix entries (``nnz``, in the order of ``indices`` past the fixed rows)
        and upper bounds (``offset``,) for the tangent at ``X_tangent`` (scaled, one per point)."""
        X = np.maximum(X_tangent, 1e-12)
        alpha, beta = 1.5 / np.sqrt(X), 0.5 / X**1.5
        x_value = self._coefficient + self._limit * beta[self._point]
        scale = np.maximum(np.maximum(self._largest, np.abs(x_value)), 1e-300)
        entries = np.where(self._is_x, x_value[self._entry_row], self._static) / scale[self._entry_row]
        return np.bincount(self.entry, weights=entries, minlength=self.nnz), self._limit * alpha[self._point] / scale
