"""A robot's kinematic tree as plain arrays, for compiled kinematics and dynamics over many
configurations (``toptraj.planners.kinematics.frame_jacobians``, ``toptraj.robots.chain_dynamics``): each
joint's placement in its parent, its axis, whether it turns or slides, which joint coordinate
moves it, and the inertia of the body it carries; and the rotation about a joint's axis
(``axis_rotation``, Rodrigues) that both compiled passes compose.

Only joints of one degree of freedom about or along a fixed axis are described: Pinocchio's
revolute (RX, RY, RZ, unaligned, and their unbounded forms, which toptraj's joint coordinates
hold as one angle) and prismatic joints (PX, PY, PZ, unaligned). A model with any other joint
has no ``Chain``; its kinematics stay with Pinocchio.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from toptraj.compiled import njit

_REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
             "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned"}
_PRISMATIC = {"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"}


@dataclass(frozen=True)
class Chain:
    """The joints of a model (Pinocchio's order, the universe left out; n joints).

    Attributes:
        parent: (n,) int64, each joint's parent joint (an index into these arrays), -1 for the
            base.
        prismatic: (n,) bool, the joint slides (else it turns).
        axis: (n, 3), the joint's unit axis in its own frame.
        rotation: (n, 3, 3), the rotation of the joint's frame at zero in its parent's frame.
        translation: (n, 3), the origin of the joint's frame in its parent's frame (m).
        coordinate: (n,) int64, the joint coordinate (tangent index) that moves the joint.
        mass: (n,), the mass of the body the joint carries (kg).
        lever: (n, 3), that body's centre of mass in the joint's frame (m).
        inertia: (n, 3, 3), its rotational inertia about the centre of mass, joint axes (kg m^2).
        armature: (n_dof,), the rotor inertia added on each joint coordinate (kg m^2 or kg).
        gravity: (3,), the gravity vector in the base frame (m/s^2).
    """

    parent: np.ndarray
    prismatic: np.ndarray
    axis: np.ndarray
    rotation: np.ndarray
    translation: np.ndarray
    coordinate: np.ndarray
    mass: np.ndarray
    lever: np.ndarray
    inertia: np.ndarray
    armature: np.ndarray
    gravity: np.ndarray


def sliding_joints(model: pin.Model) -> np.ndarray:
    """Whether each velocity coordinate (model.nv,) belongs to a prismatic joint (``_PRISMATIC``),
    whose limits are in m/s, m/s^2, m/s^3 and N rather than rad/s ... and N m."""
    sliding = np.zeros(model.nv, dtype=bool)
    for joint in list(model.joints)[1:]:
        if joint.nv == 1 and joint.shortname() in _PRISMATIC:
            sliding[joint.idx_v] = True
    return sliding


def chain_of(model: pin.Model) -> Chain | None:
    """The ``Chain`` of ``model``, or ``None`` when it has a joint other than a revolute or a
    prismatic one. Each axis is read from the joint's motion subspace (its angular part for a
    revolute joint, its linear part for a prismatic one)."""
    joints = list(model.joints)[1:]
    if any(joint.shortname() not in _REVOLUTE | _PRISMATIC or joint.nv != 1 for joint in joints):
        return None
    axes, prismatic = [], []
    for joint in joints:
        data = joint.createData()
        joint.calc(data, np.array([1.0, 0.0]) if joint.nq == 2 else np.zeros(joint.nq))
        motion = np.asarray(data.S, dtype=float).ravel()
        slides = joint.shortname() in _PRISMATIC
        axes.append(motion[:3] if slides else motion[3:])
        prismatic.append(slides)
    placements = [model.jointPlacements[index] for index in range(1, model.njoints)]
    bodies = [model.inertias[index] for index in range(1, model.njoints)]
    return Chain(
        parent=np.asarray([model.parents[index] - 1 for index in range(1, model.njoints)], dtype=np.int64),
        prismatic=np.asarray(prismatic, dtype=np.bool_),
        axis=np.ascontiguousarray(axes, dtype=float),
        rotation=np.ascontiguousarray([placement.rotation for placement in placements], dtype=float),
        translation=np.ascontiguousarray([placement.translation for placement in placements], dtype=float),
        coordinate=np.asarray([joint.idx_v for joint in joints], dtype=np.int64),
        mass=np.asarray([body.mass for body in bodies], dtype=float),
        lever=np.ascontiguousarray([body.lever for body in bodies], dtype=float).reshape(-1, 3),
        inertia=np.ascontiguousarray([body.inertia for body in bodies], dtype=float).reshape(-1, 3, 3),
        armature=np.asarray(model.armature, dtype=float).copy(),
        gravity=np.asarray(model.gravity.linear, dtype=float).copy(),
    )


@njit(cache=True, nogil=True)
def axis_rotation(axis, angle, out) -> None:  # pragma: no cover - compiled
    """Rot(axis, angle) = I + sin(angle) [axis]x + (1 - cos(angle)) [axis]x^2 (Rodrigues) of the
    unit ``axis`` (3,) by ``angle`` (rad) into ``out`` (3, 3)."""
    sine, versine = np.sin(angle), 1.0 - np.cos(angle)
    x, y, z = axis[0], axis[1], axis[2]
    out[0, 0] = 1.0 - versine * (y * y + z * z)
    out[1, 1] = 1.0 - versine * (x * x + z * z)
    out[2, 2] = 1.0 - versine * (x * x + y * y)
    out[0, 1] = versine * x * y - sine * z
    out[1, 0] = versine * x * y + sine * z
    out[0, 2] = versine * x * z + sine * y
    out[2, 0] = versine * x * z - sine * y
    out[1, 2] = versine * y * z - sine * x
    out[2, 1] = versine * y * z + sine * x
