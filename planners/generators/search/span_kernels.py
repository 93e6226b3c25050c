"""Compiled configurations along the search's spans (``free_space.clear_pieces``): the uniform
cubic B-spline of ``curve`` evaluated at one local parameter per configuration, reading the
span's control points in place instead of gathering a copy of them per configuration.

    q(t) = sum_j (sum_p t^p BASIS[p, j]) P_j,   j = 0 ... 3                          (curve.BASIS)

Shapes: control points (K, 4, n_dof) in rad or m; span indices and parameters (k,); q (k, n_dof).
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit


@njit(cache=True, nogil=True)
def span_points(control, span, t, basis):  # pragma: no cover - compiled
    """q (k, n_dof) of span ``span[i]`` (control points ``control`` (K, 4, n_dof)) at local
    parameter ``t[i]`` in [0, 1], ``basis`` the (4, 4) matrix ``curve.BASIS`` (rows: powers
    of t, columns: control points)."""
    k, n = span.shape[0], control.shape[2]
    out = np.empty((k, n))
    for i in range(k):
        x = t[i]
        x2 = x * x
        x3 = x2 * x
        s = span[i]
        w0 = basis[0, 0] + x * basis[1, 0] + x2 * basis[2, 0] + x3 * basis[3, 0]
        w1 = basis[0, 1] + x * basis[1, 1] + x2 * basis[2, 1] + x3 * basis[3, 1]
        w2 = basis[0, 2] + x * basis[1, 2] + x2 * basis[2, 2] + x3 * basis[3, 2]
        w3 = basis[0, 3] + x * basis[1, 3] + x2 * basis[2, 3] + x3 * basis[3, 3]
        for j in range(n):
            out[i, j] = w0 * control[s, 0, j] + w1 * control[s, 1, j] + w2 * control[s, 2, j] + w3 * control[s, 3, j]
    return out
