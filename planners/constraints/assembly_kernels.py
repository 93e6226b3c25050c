"""Compiled assembly of the constraint rows (numba): from the path's s-derivatives and three
RNEA evaluations per point to the rows ``a u + b x + c + d sd`` and the first-order bound
sd_max, in one pass over the grid. ``toptraj.planners.constraints.path_constraints`` says what the rows mean; this
module only writes them (``nogil``, cached on disk, no knowledge of paths or robots).
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit


@njit(cache=True, nogil=True)
def assemble_rows(dq, ddq, tau, coulomb, viscous, acceleration_joints, acceleration, torque_joints, torque, a, b, c, d, lower, upper):  # pragma: no cover - compiled
    """Write the second-order rows of n grid points into ``a, b, c, d, lower, upper`` (each
    (n, m), m = len(acceleration_joints) + len(torque_joints); acceleration rows first).

    Jeong & Lee eq. (3.4b)/(3.6) with x = sd^2 and u = sdd:

    * acceleration of joint j: ``q'_j u + q''_j x`` within +-acceleration[j] (rad/s^2);
    * torque of joint j: with g = RNEA(q, 0, 0), ``(RNEA(q, 0, q') - g) u +
      (RNEA(q, q', q'') - g) x + g + F_j sign(q'_j) + D_j q'_j sd`` within +-torque[j] (N m).

    Args:
        dq, ddq: q' and q'' at the points, (n, n_dof).
        tau: (3 n, n_dof): RNEA(q, 0, 0), RNEA(q, 0, q') and RNEA(q, q', q'') of every point,
            in three blocks of n rows; unused (may be (0, n_dof)) without torque rows.
        coulomb, viscous: Joint friction F and D, (n_dof,).
        acceleration_joints, torque_joints: Joints whose limits are rows (finite limits).
        acceleration, torque: Limits per joint, (n_dof,).
    """
    n = dq.shape[0]
    k = 0
    for j in acceleration_joints:
        bound = acceleration[j]
        for i in range(n):
            a[i, k] = dq[i, j]
            b[i, k] = ddq[i, j]
            c[i, k] = 0.0
            d[i, k] = 0.0
            lower[i, k] = -bound
            upper[i, k] = bound
        k += 1
    for j in torque_joints:
        bound = torque[j]
        for i in range(n):
            g = tau[i, j]
            a[i, k] = tau[n + i, j] - g
            b[i, k] = tau[2 * n + i, j] - g
            slope = dq[i, j]
            sign = 1.0 if slope > 0.0 else (-1.0 if slope < 0.0 else 0.0)
            c[i, k] = g + coulomb[j] * sign
            d[i, k] = viscous[j] * slope
            lower[i, k] = -bound
            upper[i, k] = bound
        k += 1


@njit(cache=True, nogil=True)
def velocity_bound(dq, velocity, sd_max, binding):  # pragma: no cover - compiled
    """sd_max[i] = min_j velocity[j] / |q'_j| (1/s; inf where no joint moves) and the joint
    ``binding[i]`` that sets it (the first of equals; -1 where sd_max is inf), for the points
    of ``dq`` (n, n_dof) and positive limits ``velocity`` (n_dof,, rad/s, inf where none)."""
    n, n_dof = dq.shape
    for i in range(n):
        best = np.inf
        joint = -1
        for j in range(n_dof):
            slope = abs(dq[i, j])
            if slope > 0.0:
                value = velocity[j] / slope
                if value < best:
                    best = value
                    joint = j
        sd_max[i] = best
        binding[i] = joint
