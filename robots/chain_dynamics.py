"""Inverse dynamics of a ``toptraj.robots.chain.Chain`` at many states in one compiled pass: the
recursive Newton-Euler algorithm (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, §5.3,
Table 5.1) with spatial vectors in each joint's frame, for several sets of joint velocities and
accelerations that share one configuration, so the joint placements are computed once per
configuration whatever the number of sets.

Per joint j with parent k, placement (R, p) of j's frame in k's (R = R_0 Rot(a, q_j) for a
revolute joint, p = t_0 + R_0 a q_j for a prismatic one), motion subspace S = (0; a) (revolute)
or (a; 0) (prismatic), spatial vectors written (linear; angular) at the frame's origin:

    v_j = X_j v_k + S qd_j                                   (Table 5.1, the velocity)
    a_j = X_j a_k + S qdd_j + v_j x S qd_j                   (the acceleration; a_0 = (-g; 0))
    f_j = I_j a_j + v_j x* I_j v_j                           (the body's force)
    tau_j = S^T f_j + armature_j qdd_j,   f_k += X_j^* f_j   (the backward pass)

where X_j moves a motion vector from k's origin and axes to j's, (v; w) -> (R^T (v + w x p);
R^T w), X_j^* moves a force back, (f; n) -> (R f; R n + p x R f), the cross products are
(v; w) x (u; z) = (w x u + v x z; w x z) and (v; w) x* (f; n) = (w x f; w x n + v x f), and
the spatial inertia of mass m, centre of mass c and rotational inertia I_c about it maps (v; w)
to (h; I_c w + c x h) with h = m (v - c x w). Pinocchio's ``rnea`` computes the same sum,
armature included; the two agree to rounding (``tests/robots/test_chain_dynamics.py``).

Shapes: q (n, n_dof) in rad or m; qd, qdd, tau (n_sets, n, n_dof) in rad/s, rad/s^2 and N m
(m/s, m/s^2 and N for a prismatic joint).
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit
from toptraj.robots.chain import Chain, axis_rotation


def chain_rnea(chain: Chain, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """Joint torques (n_sets, n, n_dof) for the configurations ``q`` (n, n_dof), each with the
    ``n_sets`` velocity and acceleration pairs ``qd[m], qdd[m]`` (each (n_sets, n, n_dof)).
    Leading sets without velocity take a shorter pass (``rnea_sets``)."""
    q = np.ascontiguousarray(q, dtype=float)
    qd = np.ascontiguousarray(qd, dtype=float)
    qdd = np.ascontiguousarray(qdd, dtype=float)
    tau = np.empty(qd.shape)
    rnea_sets(
        q, qd, qdd, chain.parent, chain.prismatic, chain.axis, chain.rotation, chain.translation, chain.coordinate,
        chain.mass, chain.lever, chain.inertia, chain.armature, chain.gravity, tau,
    )
    return tau


@njit(cache=True, nogil=True, inline="always")
def _cross(x0, x1, x2, y0, y1, y2):  # pragma: no cover - compiled
    """x x y of two 3-vectors given by their components."""
    return x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0


@njit(cache=True, nogil=True, inline="always")
def _inertia_times(mass, lever, inertia, v0, v1, v2, w0, w1, w2):  # pragma: no cover - compiled
    """The spatial inertia (mass, lever (3,), inertia (3, 3) about the centre of mass) times
    the motion (v; w): (h; I_c w + c x h) with h = m (v - c x w)."""
    c0, c1, c2 = lever[0], lever[1], lever[2]
    x0, x1, x2 = _cross(c0, c1, c2, w0, w1, w2)
    h0, h1, h2 = mass * (v0 - x0), mass * (v1 - x1), mass * (v2 - x2)
    y0, y1, y2 = _cross(c0, c1, c2, h0, h1, h2)
    n0 = inertia[0, 0] * w0 + inertia[0, 1] * w1 + inertia[0, 2] * w2 + y0
    n1 = inertia[1, 0] * w0 + inertia[1, 1] * w1 + inertia[1, 2] * w2 + y1
    n2 = inertia[2, 0] * w0 + inertia[2, 1] * w1 + inertia[2, 2] * w2 + y2
    return h0, h1, h2, n0, n1, n2


@njit(cache=True, nogil=True)
def _placements(q_row, prismatic, axis, rotation, translation, coordinate, turn, out_rotation, out_origin):  # pragma: no cover - compiled
    """Each joint's frame in its parent's at the configuration ``q_row`` (n_dof,): rotations
    (n_joints, 3, 3) and origins (n_joints, 3) into the two outputs (``turn``: (3, 3) scratch)."""
    for j in range(axis.shape[0]):
        value = q_row[coordinate[j]]
        x, y, z = axis[j, 0], axis[j, 1], axis[j, 2]
        if prismatic[j]:
            for row in range(3):
                for column in range(3):
                    out_rotation[j, row, column] = rotation[j, row, column]
                slide = rotation[j, row, 0] * x + rotation[j, row, 1] * y + rotation[j, row, 2] * z
                out_origin[j, row] = translation[j, row] + slide * value
            continue
        axis_rotation(axis[j], value, turn)
        for row in range(3):
            for column in range(3):
                out_rotation[j, row, column] = (
                    rotation[j, row, 0] * turn[0, column] + rotation[j, row, 1] * turn[1, column] + rotation[j, row, 2] * turn[2, column]
                )
            out_origin[j, row] = translation[j, row]


@njit(cache=True, nogil=True)
def rnea_sets(q, qd, qdd, parent, prismatic, axis, rotation, translation, coordinate, mass, lever, inertia, armature, gravity, tau) -> None:  # pragma: no cover - compiled
    """The torques of every set at every configuration into ``tau`` (n_sets, n, n_dof); the
    chain's arrays as ``toptraj.robots.chain.Chain`` holds them (joints ordered parents first). Leading
    sets whose velocities are all zero (the build's g and M q' + g) take Table 5.1 without the
    terms that vanish with v (v_j = 0, a_j = X_j a_k + S qdd_j, f_j = I_j a_j): the same
    numbers with a third of the forward pass's work."""
    n_joints = parent.shape[0]
    n_sets = qd.shape[0]
    placed = np.empty((n_joints, 3, 3))
    origin = np.empty((n_joints, 3))
    motion = np.empty((n_sets, n_joints, 6))  # velocity (linear; angular), joint axes
    acceleration = np.empty((n_sets, n_joints, 6))
    force = np.empty((n_sets, n_joints, 6))  # (force; moment about the joint's origin)
    turn = np.empty((3, 3))
    rest = 0
    while rest < n_sets and not np.any(qd[rest]):
        rest += 1
    for sample in range(q.shape[0]):
        _placements(q[sample], prismatic, axis, rotation, translation, coordinate, turn, placed, origin)
        for j in range(n_joints):
            k, i = parent[j], coordinate[j]
            R, p = placed[j], origin[j]
            a0, a1, a2 = axis[j, 0], axis[j, 1], axis[j, 2]
            for m in range(rest):  # at rest: no velocity, no velocity-product or bias terms
                if k < 0:
                    b = (-gravity[0], -gravity[1], -gravity[2], 0.0, 0.0, 0.0)
                else:
                    pa = acceleration[m, k]
                    y0, y1, y2 = _cross(pa[3], pa[4], pa[5], p[0], p[1], p[2])
                    b = (pa[0] + y0, pa[1] + y1, pa[2] + y2, pa[3], pa[4], pa[5])
                acc = acceleration[m, j]
                for row in range(3):
                    acc[row] = R[0, row] * b[0] + R[1, row] * b[1] + R[2, row] * b[2]
                    acc[3 + row] = R[0, row] * b[3] + R[1, row] * b[4] + R[2, row] * b[5]
                rate = qdd[m, sample, i]
                first = 0 if prismatic[j] else 3  # S qdd: along the axis, linear or angular
                acc[first] += a0 * rate
                acc[first + 1] += a1 * rate
                acc[first + 2] += a2 * rate
                f0, f1, f2, t0, t1, t2 = _inertia_times(mass[j], lever[j], inertia[j], acc[0], acc[1], acc[2], acc[3], acc[4], acc[5])
                f = force[m, j]
                f[0], f[1], f[2] = f0, f1, f2
                f[3], f[4], f[5] = t0, t1, t2
            for m in range(rest, n_sets):
                # the parent's velocity and acceleration at this origin, parent axes
                if k < 0:
                    u = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
                    b = (-gravity[0], -gravity[1], -gravity[2], 0.0, 0.0, 0.0)
                else:
                    pv, pa = motion[m, k], acceleration[m, k]
                    x0, x1, x2 = _cross(pv[3], pv[4], pv[5], p[0], p[1], p[2])
                    y0, y1, y2 = _cross(pa[3], pa[4], pa[5], p[0], p[1], p[2])
                    u = (pv[0] + x0, pv[1] + x1, pv[2] + x2, pv[3], pv[4], pv[5])
                    b = (pa[0] + y0, pa[1] + y1, pa[2] + y2, pa[3], pa[4], pa[5])
                v, acc = motion[m, j], acceleration[m, j]
                for row in range(3):  # rotated into this joint's axes: R^T
                    v[row] = R[0, row] * u[0] + R[1, row] * u[1] + R[2, row] * u[2]
                    v[3 + row] = R[0, row] * u[3] + R[1, row] * u[4] + R[2, row] * u[5]
                    acc[row] = R[0, row] * b[0] + R[1, row] * b[1] + R[2, row] * b[2]
                    acc[3 + row] = R[0, row] * b[3] + R[1, row] * b[4] + R[2, row] * b[5]
                speed, rate = qd[m, sample, i], qdd[m, sample, i]
                if prismatic[j]:  # v x (a; 0) = (w x a; 0)
                    c0, c1, c2 = _cross(v[3], v[4], v[5], a0, a1, a2)
                    acc[0] += c0 * speed + a0 * rate
                    acc[1] += c1 * speed + a1 * rate
                    acc[2] += c2 * speed + a2 * rate
                    v[0] += a0 * speed
                    v[1] += a1 * speed
                    v[2] += a2 * speed
                else:  # v x (0; a) = (v x a; w x a)
                    c0, c1, c2 = _cross(v[0], v[1], v[2], a0, a1, a2)
                    d0, d1, d2 = _cross(v[3], v[4], v[5], a0, a1, a2)
                    acc[0] += c0 * speed
                    acc[1] += c1 * speed
                    acc[2] += c2 * speed
                    acc[3] += d0 * speed + a0 * rate
                    acc[4] += d1 * speed + a1 * rate
                    acc[5] += d2 * speed + a2 * rate
                    v[3] += a0 * speed
                    v[4] += a1 * speed
                    v[5] += a2 * speed
                h0, h1, h2, n0, n1, n2 = _inertia_times(mass[j], lever[j], inertia[j], v[0], v[1], v[2], v[3], v[4], v[5])
                f0, f1, f2, t0, t1, t2 = _inertia_times(mass[j], lever[j], inertia[j], acc[0], acc[1], acc[2], acc[3], acc[4], acc[5])
                x0, x1, x2 = _cross(v[3], v[4], v[5], h0, h1, h2)  # v x* (h; n) = (w x h; w x n + v x h)
                y0, y1, y2 = _cross(v[3], v[4], v[5], n0, n1, n2)
                z0, z1, z2 = _cross(v[0], v[1], v[2], h0, h1, h2)
                f = force[m, j]
                f[0], f[1], f[2] = f0 + x0, f1 + x1, f2 + x2
                f[3], f[4], f[5] = t0 + y0 + z0, t1 + y1 + z1, t2 + y2 + z2
        for j in range(n_joints - 1, -1, -1):
            k, i = parent[j], coordinate[j]
            R, p = placed[j], origin[j]
            first = 0 if prismatic[j] else 3
            for m in range(n_sets):
                f = force[m, j]
                projected = axis[j, 0] * f[first] + axis[j, 1] * f[first + 1] + axis[j, 2] * f[first + 2]
                tau[m, sample, i] = projected + armature[i] * qdd[m, sample, i]
                if k < 0:
                    continue
                g0 = R[0, 0] * f[0] + R[0, 1] * f[1] + R[0, 2] * f[2]  # X^* f: (R f; R n + p x R f)
                g1 = R[1, 0] * f[0] + R[1, 1] * f[1] + R[1, 2] * f[2]
                g2 = R[2, 0] * f[0] + R[2, 1] * f[1] + R[2, 2] * f[2]
                e0, e1, e2 = _cross(p[0], p[1], p[2], g0, g1, g2)
                into = force[m, k]
                into[0] += g0
                into[1] += g1
                into[2] += g2
                into[3] += R[0, 0] * f[3] + R[0, 1] * f[4] + R[0, 2] * f[5] + e0
                into[4] += R[1, 0] * f[3] + R[1, 1] * f[4] + R[1, 2] * f[5] + e1
                into[5] += R[2, 0] * f[3] + R[2, 1] * f[4] + R[2, 2] * f[5] + e2
