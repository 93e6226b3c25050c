"""The ``Robot``: a Pinocchio model with its joint names, end effector and limits.

Joint coordinates inside toptraj are always the model's tangent coordinates, one angle (or
length) per degree of freedom, shape ``(n_dof,)`` or ``(n_samples, n_dof)``. Continuous joints,
which Pinocchio stores as a (cos, sin) pair, are converted at this boundary, so an elbow may turn
through -2 pi without any wrap-around.
"""

from __future__ import annotations

import dataclasses
import threading
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from toptraj.robots.chain import Chain, chain_of, sliding_joints
from toptraj.robots.chain_dynamics import chain_rnea
from toptraj.robots.limits import JointLimits

if TYPE_CHECKING:
    from toptraj.robots.equipment import Mounting, Payload


def _is_continuous(joint) -> bool:
    """A joint that Pinocchio stores as a (cos, sin) pair: a revolute joint without limits."""
    return joint.nq == 2 and joint.nv == 1


def tangent_position_limits(model: pin.Model) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper position limits per degree of freedom, shape (n_dof,) each; continuous
    joints unlimited (Pinocchio indexes its limits by configuration coordinate)."""
    lower = np.full(model.nv, -np.inf)
    upper = np.full(model.nv, np.inf)
    for joint in model.joints[1:]:
        if not _is_continuous(joint):
            lower[joint.idx_v : joint.idx_v + joint.nv] = model.lowerPositionLimit[joint.idx_q : joint.idx_q + joint.nq]
            upper[joint.idx_v : joint.idx_v + joint.nv] = model.upperPositionLimit[joint.idx_q : joint.idx_q + joint.nq]
    return lower, upper


@dataclass(frozen=True)
class Robot:
    """A fixed-base arm ready for dynamics.

    Attributes:
        name: Catalog name.
        model: The Pinocchio model (public contract: ``robots.load(name).model``).
        source: ``"bundled"``, ``"example-robot-data"`` or ``"upload"``.
        joint_names: Names of the actuated joints, in model order, length n_dof.
        end_effector: Name of the frame used for Cartesian paths and conditioning.
        limits: Joint limits, URDF values completed by ``robots/data/limits.toml``.
        continuous: Boolean mask, shape (n_dof,): joints without position limits.
        viscous_friction: Joint damping from the URDF, shape (n_dof,), in N m s/rad.
        coulomb_friction: Joint dry friction from the URDF, shape (n_dof,), in N m.
        limit_sources: {limit kind: where each joint's limit comes from} ("urdf",
            "limits.toml", "joint_limits.yaml", "default: ..."); empty when not recorded.
        locked_joints: Joints of the URDF fixed at a value (rad, m), not among ``joint_names``.
        notes: What a user of the robot should know (ignored meshes, limits not applied).
        payload: What the model carries at its tool (``toptraj.robots.equipment``), ``None``: nothing.
        mounting: The base pose in the world and the world's gravity written into the model,
            ``None``: the base frame is the world.
        bare: The robot without payload and mounting when this one has either, else ``None``.
        allowed_collisions: Pairs of links (sorted names) allowed to touch: not checked for
            self-collision (``toptraj.planners.collision.self_collision``).
    """

    name: str
    model: pin.Model
    source: str
    joint_names: tuple[str, ...]
    end_effector: str
    limits: JointLimits
    continuous: np.ndarray
    viscous_friction: np.ndarray
    coulomb_friction: np.ndarray
    _cos_index: np.ndarray = field(repr=False)
    _angle_index_of_pair: np.ndarray = field(repr=False)
    _plain_q_index: np.ndarray = field(repr=False)
    _plain_v_index: np.ndarray = field(repr=False)
    _identity_configuration: bool = field(default=False, repr=False, compare=False)
    _local: threading.local = field(default_factory=threading.local, repr=False, compare=False)
    limit_sources: dict[str, tuple[str, ...]] = field(default_factory=dict, repr=False, compare=False)
    locked_joints: dict[str, float] = field(default_factory=dict, repr=False, compare=False)
    notes: tuple[str, ...] = field(default=(), repr=False, compare=False)
    payload: Payload | None = field(default=None, compare=False)
    mounting: Mounting | None = field(default=None, compare=False)
    bare: Robot | None = field(default=None, repr=False, compare=False)
    allowed_collisions: frozenset[tuple[str, str]] = field(default_factory=frozenset, repr=False, compare=False)

    @classmethod
    def from_model(
        cls,
        name: str,
        model: pin.Model,
        source: str,
        end_effector: str,
        limits: JointLimits,
        limit_sources: dict[str, tuple[str, ...]] | None = None,
        locked_joints: dict[str, float] | None = None,
        notes: tuple[str, ...] = (),
        payload: Payload | None = None,
        mounting: Mounting | None = None,
        bare: Robot | None = None,
    ) -> Robot:
        """Wrap ``model``, precomputing the map from tangent coordinates to Pinocchio's q
        (``payload``, ``mounting`` and ``bare``: what ``toptraj.robots.equipment.equip`` wrote into it)."""
        cos_index: list[int] = []
        pair_angle: list[int] = []
        plain_q: list[int] = []
        plain_v: list[int] = []
        continuous = np.zeros(model.nv, dtype=bool)
        for joint in model.joints[1:]:
            if _is_continuous(joint):
                cos_index.append(joint.idx_q)
                pair_angle.append(joint.idx_v)
                continuous[joint.idx_v] = True
            else:
                plain_q.extend(range(joint.idx_q, joint.idx_q + joint.nq))
                plain_v.extend(range(joint.idx_v, joint.idx_v + joint.nv))
        return cls(
            name=name,
            model=model,
            source=source,
            joint_names=tuple(model.names[1:]),
            end_effector=end_effector,
            limits=limits,
            continuous=continuous,
            viscous_friction=np.asarray(model.damping, dtype=float).copy(),
            coulomb_friction=np.asarray(model.friction, dtype=float).copy(),
            _cos_index=np.asarray(cos_index, dtype=int),
            _angle_index_of_pair=np.asarray(pair_angle, dtype=int),
            _plain_q_index=np.asarray(plain_q, dtype=int),
            _plain_v_index=np.asarray(plain_v, dtype=int),
            _identity_configuration=not cos_index and plain_q == list(range(model.nq)) and plain_v == list(range(model.nv)),
            limit_sources=dict(limit_sources or {}),
            locked_joints=dict(locked_joints or {}),
            notes=tuple(notes),
            payload=payload,
            mounting=mounting,
            bare=bare,
        )

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its model and metadata (the per-thread workspaces are rebuilt), so that a
        robot can be sent to a worker process."""
        return _rebuilt, (
            self.name, self.model, self.source, self.end_effector, self.limits, self.limit_sources, self.locked_joints, self.notes,
            self.payload, self.mounting, self.bare, self.allowed_collisions,
        )

    @cached_property
    def chain(self) -> Chain | None:
        """The kinematic tree as arrays (``toptraj.robots.chain``), ``None`` when a joint is neither
        revolute nor prismatic."""
        return chain_of(self.model)

    @cached_property
    def neutral_reach(self) -> float:
        """Distance (m) from the first joint to the ``end_effector`` frame at the neutral
        posture (computed once; the model never changes)."""
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))
        return float(np.linalg.norm(data.oMf[self.frame_id(self.end_effector)].translation - data.oMi[1].translation))

    @cached_property
    def force_units(self) -> tuple[str, ...]:
        """The unit of each joint's torque (n_dof,): "N m", or "N" for a prismatic joint
        (computed once)."""
        return tuple("N" if sliding else "N m" for sliding in sliding_joints(self.model))

    @cached_property
    def has_friction(self) -> bool:
        """Whether any joint has viscous or Coulomb friction (computed once)."""
        return bool(np.any(self.viscous_friction) or np.any(self.coulomb_friction))

    @cached_property
    def has_coulomb_friction(self) -> bool:
        """Whether any joint has Coulomb (dry) friction (computed once)."""
        return bool(np.any(self.coulomb_friction))

    @cached_property
    def dof(self) -> int:
        """Number of degrees of freedom (actuated joints; read once, the model never changes)."""
        return self.model.nv

    @property
    def data(self) -> pin.Data:
        """Pinocchio workspace of the calling thread (models are shared, data never is)."""
        data = getattr(self._local, "data", None)
        if data is None:
            data = self._local.data = self.model.createData()
        return data

    def configuration(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio's configurations, shape (..., nq), from joint coordinates (..., n_dof)."""
        if self._identity_configuration:  # Pinocchio's q is the joint coordinates in order
            return np.array(q, dtype=float)
        q = np.asarray(q, dtype=float)
        out = np.empty(q.shape[:-1] + (self.model.nq,))
        out[..., self._plain_q_index] = q[..., self._plain_v_index]
        angles = q[..., self._angle_index_of_pair]
        out[..., self._cos_index] = np.cos(angles)
        out[..., self._cos_index + 1] = np.sin(angles)
        return out

    def rnea(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Inverse dynamics (Pinocchio's RNEA, armature included) for rows of ``q, qd, qdd``
        (each (n_samples, n_dof)); shape (n_samples, n_dof), N m (N). Arms with a ``chain``
        take the compiled pass of ``toptraj.robots.chain_dynamics``, the others one batched Pinocchio
        call on the calling thread's model pool."""
        qd = np.atleast_2d(qd)
        return self.rnea_sets(q, qd[np.newaxis], np.atleast_2d(qdd)[np.newaxis])[0]

    def rnea_sets(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Inverse dynamics at the configurations ``q`` (n, n_dof), each with ``n_sets`` pairs
        of velocities and accelerations ``qd[m], qdd[m]`` (each (n_sets, n, n_dof)): shape
        (n_sets, n, n_dof), each set's rows C-contiguous (orjson writes them directly). With a
        ``chain`` the sets share one computation of the joint placements."""
        q = np.atleast_2d(q)
        qd, qdd = np.asarray(qd, dtype=float), np.asarray(qdd, dtype=float)
        if q.shape[0] == 0:
            return np.empty(qd.shape)
        if self.chain is not None:
            return chain_rnea(self.chain, q, qd, qdd)
        pool = getattr(self._local, "pool", None)
        if pool is None:
            pool = self._local.pool = pin.ModelPool(self.model, 1)
        n_sets, n = qd.shape[:2]
        tau = pin.rneaInParallel(
            1,
            pool,
            np.asfortranarray(np.tile(self.configuration(q), (n_sets, 1)).T),
            np.asfortranarray(qd.reshape(n_sets * n, -1).T),
            np.asfortranarray(qdd.reshape(n_sets * n, -1).T),
        )
        return np.ascontiguousarray(np.asarray(tau).T).reshape(qd.shape)

    def inverse_dynamics(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, direction: np.ndarray | None = None) -> np.ndarray:
        """Joint torques for rows of ``q, qd, qdd`` (each (n_samples, n_dof)): the RNEA
        (``rnea``) plus the URDF's viscous and Coulomb joint friction, ``D qd + F sign(qd)``.
        ``direction`` (same shape): where a joint's qd is zero, the sign of the motion its
        Coulomb friction opposes (along a path, its tangent q' at a stop: the friction just
        before or after it, as the planning held it); ``None``: none there."""
        qd = np.atleast_2d(qd)
        tau = self.rnea(q, qd, qdd)
        if self.has_friction:
            tau += self.viscous_friction * qd + self.coulomb_friction * friction_sign(qd, direction)
        return tau

    def outside_position_limits(self, q: np.ndarray, slack: float = 1e-9) -> tuple[int, int] | None:
        """(row, joint) of the first value of ``q`` (n_samples, n_dof) outside the joint's
        position limits by more than ``slack``, or ``None`` when all are inside."""
        q = np.atleast_2d(q)
        outside = (q < self.limits.position_lower - slack) | (q > self.limits.position_upper + slack)
        if not outside.any():
            return None
        row, joint = np.argwhere(outside)[0]
        return int(row), int(joint)

    def frame_id(self, frame: str) -> int:
        """Index of ``frame`` in the model; ``KeyError`` when it has no such frame (looked up
        once per name: the model never changes)."""
        known = self._frame_ids
        if frame not in known:
            known[frame] = frame_index(self.model, frame)
        return known[frame]

    def frame_anchor(self, frame_id: int) -> tuple[int, np.ndarray]:
        """The joint that carries frame ``frame_id`` (its index among the joints, -1 for the
        universe) and the frame's origin in that joint's frame, (3,) in m (computed once per
        frame; not to be written)."""
        anchors = self._frame_anchors
        if frame_id not in anchors:
            placed = self.model.frames[frame_id]
            origin = np.array(placed.placement.translation, dtype=float)
            anchors[frame_id] = (int(placed.parentJoint) - 1, origin)
        return anchors[frame_id]

    @cached_property
    def _frame_ids(self) -> dict[str, int]:
        return {}

    @cached_property
    def _frame_anchors(self) -> dict[int, tuple[int, np.ndarray]]:
        return {}


def _rebuilt(name, model, source, end_effector, limits, limit_sources, locked_joints, notes, payload, mounting, bare,
             allowed_collisions) -> Robot:
    """A pickled ``Robot`` rebuilt (``Robot.__reduce__``)."""
    robot = Robot.from_model(name, model, source, end_effector, limits, limit_sources, locked_joints, notes, payload, mounting, bare)
    return dataclasses.replace(robot, allowed_collisions=allowed_collisions) if allowed_collisions else robot


def friction_sign(qd: np.ndarray, direction: np.ndarray | None = None) -> np.ndarray:
    """The sign of the motion Coulomb friction opposes, per sample and joint (the shape of
    ``qd``): sign(qd), and where qd is zero the sign of ``direction`` (``Robot.inverse_dynamics``)."""
    return np.sign(qd) if direction is None else np.where(qd != 0.0, np.sign(qd), np.sign(direction))


def frame_index(model: pin.Model, name: str) -> int:
    """Index of the frame ``name`` in ``model``: its link (a body frame) where a joint bears the
    same name, as a URDF may give a link and a joint one name (pinocchio's ``getFrameId``
    refuses the ambiguity); ``KeyError`` when no frame has that name."""
    matches = [index for index, frame in enumerate(model.frames) if frame.name == name]
    if not matches:
        raise KeyError(name)
    bodies = [index for index in matches if model.frames[index].type == pin.FrameType.BODY]
    return (bodies or matches)[0]
