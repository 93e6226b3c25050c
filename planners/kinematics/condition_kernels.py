"""Compiled Frobenius condition numbers of a stack of small Jacobians (numba), from their Gram
matrices: ``toptraj.planners.kinematics.conditioning`` says what the number means and when the singular
values must decide instead. No knowledge of robots (``nogil``, cached on disk)."""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit


@njit(cache=True, nogil=True)
def gram_condition_numbers(stack, kappa):  # pragma: no cover - compiled
    """kappa_F = sqrt(tr G tr G^-1) / k of every matrix J of ``stack`` (s, m, n) into ``kappa``
    (s,), with G = J^T J (m >= n) or J J^T (m < n), k = min(m, n). tr G^-1 is the squared
    Frobenius norm of L^-1, L the Cholesky factor of G (G^-1 = L^-T L^-1); inf where G is not
    positive definite to rounding (a pivot <= 0)."""
    count_stack, m, n = stack.shape
    k = min(m, n)
    gram = np.empty((k, k))
    lower = np.empty((k, k))
    inverse = np.empty((k, k))
    for index in range(count_stack):
        for row in range(k):
            for column in range(row + 1):
                total = 0.0
                if m >= n:
                    for inner in range(m):
                        total += stack[index, inner, row] * stack[index, inner, column]
                else:
                    for inner in range(n):
                        total += stack[index, row, inner] * stack[index, column, inner]
                gram[row, column] = total
        trace = 0.0
        for row in range(k):
            trace += gram[row, row]
        definite = True
        for column in range(k):
            pivot = gram[column, column]
            for inner in range(column):
                pivot -= lower[column, inner] ** 2
            if not pivot > 0.0:
                definite = False
                break
            lower[column, column] = np.sqrt(pivot)
            for row in range(column + 1, k):
                total = gram[row, column]
                for inner in range(column):
                    total -= lower[row, inner] * lower[column, inner]
                lower[row, column] = total / lower[column, column]
        if not definite:
            kappa[index] = np.inf
            continue
        # L^-1 by forward substitution, column by column; tr G^-1 = ||L^-1||_F^2.
        squares = 0.0
        for column in range(k):
            for row in range(k):
                if row < column:
                    inverse[row, column] = 0.0
                    continue
                total = 1.0 if row == column else 0.0
                for inner in range(column, row):
                    total -= lower[row, inner] * inverse[inner, column]
                inverse[row, column] = total / lower[row, row]
                squares += inverse[row, column] ** 2
        kappa[index] = np.sqrt(trace * squares) / k

