"""A frame's Jacobian at many configurations in one compiled pass, for arms whose joints all turn
about or slide along a fixed axis (``toptraj.robots.chain``); other arms take one Pinocchio call per
configuration.

Forward kinematics composes each joint's frame from its parent's: with the placement (R_0, t_0)
of joint j in its parent's frame, its axis a and coordinate q_j,

    R_j = R_parent R_0 Rot(a, q_j),   p_j = p_parent + R_parent t_0          (revolute)
    R_j = R_parent R_0,               p_j = p_parent + R_parent t_0 + z_j q_j (prismatic)

with z_j = R_parent R_0 a the joint's axis in world axes and Rot(a, q) = I + sin q [a]x +
(1 - cos q) [a]x^2 (Rodrigues). The frame's Jacobian, linear velocity of its origin p_f then
angular velocity, both in world axes (Pinocchio's ``LOCAL_WORLD_ALIGNED``), has for each joint
j between the frame and the base the column (Siciliano et al., *Robotics: Modelling, Planning
and Control*, eq. (3.30))

    [z_j x (p_f - p_j); z_j]   (revolute),    [z_j; 0]   (prismatic),

and zero columns for the other joints. Shapes: q (n, n_dof) in rad or m, Jacobians
(n, 6, n_dof), linear rows in m/rad (m/m), angular rows in rad/rad (rad/m).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from toptraj.compiled import njit
from toptraj.robots import Robot
from toptraj.robots.chain import axis_rotation


def frame_jacobians(robot: Robot, frame_id: int, q: np.ndarray) -> np.ndarray:
    """The Jacobian of frame ``frame_id`` at every row of ``q`` (n, n_dof): shape (n, 6, n_dof),
    linear rows then angular rows, world-aligned axes (Pinocchio's ``computeFrameJacobian`` in
    ``LOCAL_WORLD_ALIGNED``)."""
    q = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
    jacobians = np.empty((len(q), 6, robot.dof))
    chain = robot.chain
    if chain is None:
        model, data, frame = robot.model, robot.data, pin.LOCAL_WORLD_ALIGNED
        for row, configuration in enumerate(robot.configuration(q)):
            # a one-joint model's Jacobian comes back as a (6,) vector
            jacobians[row] = np.reshape(pin.computeFrameJacobian(model, data, configuration, frame_id, frame), (6, robot.dof))
        return jacobians
    joint, origin = robot.frame_anchor(frame_id)
    chain_jacobians(
        q, chain.parent, chain.prismatic, chain.axis, chain.rotation, chain.translation, chain.coordinate, joint, origin, jacobians,
    )
    return jacobians


@njit(cache=True, nogil=True)
def chain_jacobians(q, parent, prismatic, axis, rotation, translation, coordinate, frame_joint, frame_translation, out) -> None:  # pragma: no cover - compiled
    """The Jacobians (n, 6, n_dof) of the frame at ``frame_translation`` (3,) in joint
    ``frame_joint``'s frame, at the rows of ``q`` (n, n_dof), into ``out``; the chain's arrays
    as ``toptraj.robots.chain.Chain`` holds them."""
    n_joints = parent.shape[0]
    frame_rotation = np.empty((n_joints, 3, 3))
    origin = np.empty((n_joints, 3))
    world_axis = np.empty((n_joints, 3))
    before = np.empty((3, 3))
    turn = np.empty((3, 3))
    tip = np.empty(3)
    for sample in range(q.shape[0]):
        for j in range(n_joints):
            k = parent[j]
            for row in range(3):
                if k < 0:
                    origin[j, row] = translation[j, row]
                    for column in range(3):
                        before[row, column] = rotation[j, row, column]
                else:
                    total = origin[k, row]
                    for inner in range(3):
                        total += frame_rotation[k, row, inner] * translation[j, inner]
                    origin[j, row] = total
                    for column in range(3):
                        total = 0.0
                        for inner in range(3):
                            total += frame_rotation[k, row, inner] * rotation[j, inner, column]
                        before[row, column] = total
            for row in range(3):
                world_axis[j, row] = before[row, 0] * axis[j, 0] + before[row, 1] * axis[j, 1] + before[row, 2] * axis[j, 2]
            value = q[sample, coordinate[j]]
            if prismatic[j]:
                for row in range(3):
                    origin[j, row] += world_axis[j, row] * value
                    for column in range(3):
                        frame_rotation[j, row, column] = before[row, column]
            else:
                axis_rotation(axis[j], value, turn)
                for row in range(3):
                    for column in range(3):
                        frame_rotation[j, row, column] = (
                            before[row, 0] * turn[0, column] + before[row, 1] * turn[1, column] + before[row, 2] * turn[2, column]
                        )
        for row in range(3):
            total = origin[frame_joint, row]
            for inner in range(3):
                total += frame_rotation[frame_joint, row, inner] * frame_translation[inner]
            tip[row] = total
        out[sample] = 0.0
        j = frame_joint
        while j >= 0:
            column = coordinate[j]
            z = world_axis[j]
            if prismatic[j]:
                for row in range(3):
                    out[sample, row, column] = z[row]
            else:
                dx, dy, dz = tip[0] - origin[j, 0], tip[1] - origin[j, 1], tip[2] - origin[j, 2]
                out[sample, 0, column] = z[1] * dz - z[2] * dy
                out[sample, 1, column] = z[2] * dx - z[0] * dz
                out[sample, 2, column] = z[0] * dy - z[1] * dx
                for row in range(3):
                    out[sample, 3 + row, column] = z[row]
            j = parent[j]
