"""Inverse dynamics of a Pinocchio model as a CasADi expression, for sparse nonlinear programs
(``toptraj.planners.generators.collocation.sparse``).

The recursive Newton-Euler algorithm (Featherstone, *Rigid Body Dynamics Algorithms*, 2008,
Table 5.1) in Pinocchio's conventions: spatial motions [v; w] and forces [f; n] in each joint's
frame, the base accelerating upward at -g so that gravity enters through the accelerations.
For joint i with parent p, placement M_i in its parent and motion subspace S_i (6,):

    X_i = M_i exp(S_i q_i),     v_i = X_i^-1 v_p + S_i qd_i,
    a_i = X_i^-1 a_p + S_i qdd_i + v_i x S_i qd_i,     f_i = I_i a_i + v_i x* I_i v_i,
    tau_i = S_i^T f_i,     f_p += X_i f_i (children first).

Joints served: 1-DoF revolute (bounded or continuous, any axis) and prismatic joints, the joints
of every arm the service loads; ``tests/planners/generators/test_sparse_collocation.py`` checks the expression
against ``pinocchio.rnea`` at random states. Units: rad (m), rad/s, rad/s^2 in; N m (N) out.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin

from toptraj.robots import Robot


def _skew(w):
    return ca.vertcat(
        ca.horzcat(0, -w[2], w[1]),
        ca.horzcat(w[2], 0, -w[0]),
        ca.horzcat(-w[1], w[0], 0),
    )


def _rotation(axis: np.ndarray, angle):
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues)."""
    k = _skew(ca.DM(axis))
    return ca.DM.eye(3) + ca.sin(angle) * k + (1 - ca.cos(angle)) * (k @ k)


def _subspaces(robot: Robot) -> list[tuple[str, np.ndarray]]:
    """("revolute" or "prismatic", unit axis in the joint frame) of every joint."""
    model = robot.model
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    kinds = []
    for i in range(1, model.njoints):
        if model.joints[i].nv != 1:
            raise ValueError(f"joint {model.names[i]!r} has {model.joints[i].nv} degrees of freedom; only 1-DoF joints are served")
        motion = np.array(data.joints[i].S).ravel()
        linear, angular = motion[:3], motion[3:]
        if np.linalg.norm(angular) > 0.5:
            kinds.append(("revolute", angular / np.linalg.norm(angular)))
        else:
            kinds.append(("prismatic", linear / np.linalg.norm(linear)))
    return kinds


def inverse_dynamics_function(robot: Robot) -> ca.Function:
    """``tau = f(q, qd, qdd)`` for ``robot``: a CasADi function of three (n_dof,) vectors in the
    robot's joint coordinates (angles for continuous joints), returning (n_dof,) torques
    without friction (Pinocchio's ``rnea``)."""
    n = robot.model.nv
    q, qd, qdd = ca.SX.sym("q", n), ca.SX.sym("qd", n), ca.SX.sym("qdd", n)
    kinds = _subspaces(robot)
    placements, forces = _forward_pass(robot.model, kinds, q, qd, qdd)
    tau = _backward_pass(robot.model, kinds, placements, forces)
    return ca.Function("rnea", [q, qd, qdd], [ca.vertcat(*tau)])


def _joint_placement(model, i: int, kind: str, axis: np.ndarray, angle):
    """(R, p) of joint ``i`` in its parent's frame moved by ``angle`` (rad or m) about or along
    ``axis``, and its motion subspace (S_lin, S_ang) (3,) each."""
    fixed = model.jointPlacements[i]
    R0, p0 = ca.DM(fixed.rotation), ca.DM(fixed.translation)
    if kind == "revolute":
        return (R0 @ _rotation(axis, angle), p0), (ca.DM.zeros(3), ca.DM(axis))
    return (R0, p0 + R0 @ ca.DM(axis) * angle), (ca.DM(axis), ca.DM.zeros(3))


def _forward_pass(model, kinds, q, qd, qdd) -> tuple[list, list]:
    """The outward recursion (module docstring): each joint's placement (R, p) in its parent
    and the force [f, n] (3,) each its body needs, f_i = I_i a_i + v_i x* I_i v_i."""
    parents = [model.parents[i] for i in range(model.njoints)]
    zero = ca.SX.zeros(3)
    placements: list = []  # (R, p) of each joint in its parent's frame, moved by the joint
    v: list = [(zero, zero)]  # (linear, angular) per body, body 0 the base
    a: list = [(ca.SX(ca.DM(-np.array(model.gravity.linear))), zero)]
    forces: list = []
    for i in range(1, model.njoints):
        k = model.joints[i].idx_v
        kind, axis = kinds[i - 1]
        (R, p), (S_lin, S_ang) = _joint_placement(model, i, kind, axis, q[k])
        placements.append((R, p))
        vp_lin, vp_ang = v[parents[i]]
        ap_lin, ap_ang = a[parents[i]]
        # X^-1 applied to the parent's motion: w' = R^T w, v' = R^T (v - p x w)
        w = R.T @ vp_ang + S_ang * qd[k]
        lin = R.T @ (vp_lin - ca.cross(p, vp_ang)) + S_lin * qd[k]
        dw = R.T @ ap_ang + S_ang * qdd[k] + ca.cross(w, S_ang * qd[k])
        dlin = (
            R.T @ (ap_lin - ca.cross(p, ap_ang)) + S_lin * qdd[k]
            + ca.cross(lin, S_ang * qd[k]) + ca.cross(w, S_lin * qd[k])
        )
        v.append((lin, w))
        a.append((dlin, dw))
        inertia = model.inertias[i]
        m, c, Ic = inertia.mass, ca.DM(inertia.lever), ca.DM(inertia.inertia)

        def apply(lin_, ang_, m=m, c=c, Ic=Ic):
            f = m * (lin_ - ca.cross(c, ang_))
            return f, Ic @ ang_ + ca.cross(c, f)

        f_a, n_a = apply(dlin, dw)
        f_v, n_v = apply(lin, w)
        # v x* (I v): f' = w x f, n' = w x n + v x f
        forces.append([f_a + ca.cross(w, f_v), n_a + ca.cross(w, n_v) + ca.cross(lin, f_v)])
    return placements, forces


def _backward_pass(model, kinds, placements: list, forces: list) -> list:
    """The inward recursion (module docstring): tau_i = S_i^T f_i, each body's force added to
    its parent's, children first; the (n_dof,) torques as a list. ``forces`` is updated."""
    tau: list = [ca.SX(0)] * model.nv
    for i in range(model.njoints - 1, 0, -1):
        k = model.joints[i].idx_v
        kind, axis = kinds[i - 1]
        f, moment = forces[i - 1]
        tau[k] = ca.dot(ca.DM(axis), moment) if kind == "revolute" else ca.dot(ca.DM(axis), f)
        parent = model.parents[i]
        if parent > 0:
            R, p = placements[i - 1]
            # X applied to the force: f' = R f, n' = R n + p x (R f)
            Rf = R @ f
            forces[parent - 1][0] = forces[parent - 1][0] + Rf
            forces[parent - 1][1] = forces[parent - 1][1] + R @ moment + ca.cross(p, Rf)
    return tau
