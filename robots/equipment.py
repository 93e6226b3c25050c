"""What a robot carries and how it stands in the world: a payload at its tool, and the pose of
its base (floor, wall or ceiling mounting) with the world's gravity.

Both are written into a copy of the robot's Pinocchio model, so that every computation that
reads the model (the RNEA of Pinocchio and of ``toptraj.robots.chain_dynamics``, the symbolic
dynamics of collocation, forward kinematics, Jacobians, the link capsules) sees them:

* The payload, of mass m, centre of mass c in the tool frame F and rotational inertia I_c about
  c in F's axes, is the spatial inertia (m, c, I_c) placed by F's placement X_F in its parent
  joint and added to that joint's body (``Model.appendBodyToJoint``; Featherstone, *Rigid Body
  Dynamics Algorithms*, 2008, eq. 2.66, the sum of rigidly joined inertias).
* The base pose (R, p), the base frame in the world, premultiplies the placement of every joint
  and frame fixed to the base, so that the model's reference frame is the world: obstacles,
  Cartesian lines and tool speeds given in the world are used as they are, and the RNEA's
  acceleration of the base, -g with g the world's gravity, is R^T (-g) in the base frame.

``equip`` builds such a variant once per distinct (robot, payload, mounting) and keeps the most
recently used ``CACHE_SIZE`` of them; the catalog robot it starts from is never changed.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from toptraj.robots.errors import ToptrajError
from toptraj.robots.ranges import BASE_POSITION, CENTER_OF_MASS, GRAVITY, PAYLOAD_INERTIA, PAYLOAD_MASS, PAYLOAD_RADIUS, Range
from toptraj.robots.robot import Robot, frame_index

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

#: Largest |R^T R - I| (entrywise) of a rotation matrix accepted; it is then made exactly
#: orthonormal (entries written with four digits, 0.7071 for cos 45 degrees, are off by 2e-5).
ROTATION_TOLERANCE = 1e-3
#: Largest |1 - |q|| of an orientation quaternion accepted; it is then normalized.
QUATERNION_TOLERANCE = 1e-3
#: Equipped robots kept per process.
CACHE_SIZE = 32


class InvalidEquipment(ToptrajError):
    """A payload or a base pose that is not physical: ``field`` names the quantity (``mass``,
    ``center_of_mass``, ``inertia``, ``frame``, ``position``, ``rotation``, ``orientation``,
    ``gravity``)."""

    title = "Invalid payload or mounting"

    def __init__(self, detail: str, field: str):
        super().__init__(detail)
        self.field = field


@dataclass(frozen=True)
class Payload:
    """A rigid body held at a frame of the robot.

    Attributes:
        mass: kg.
        center_of_mass: (3,) tuple, the centre of mass in ``frame`` (m).
        inertia: (9,) tuple, the rotational inertia about the centre of mass in ``frame``'s
            axes, row by row (kg m^2); zeros for a point mass.
        frame: The frame holding it; ``None``: the robot's end effector.
        radius: Radius (m) of a sphere about the centre of mass that collides with obstacles,
            other arms and the robot's own links (``toptraj.robots.collision``); 0: none.
    """

    mass: float
    center_of_mass: tuple[float, ...] = (0.0, 0.0, 0.0)
    inertia: tuple[float, ...] = (0.0,) * 9
    frame: str | None = None
    radius: float = 0.0


@dataclass(frozen=True)
class Mounting:
    """The robot's base in the world.

    Attributes:
        position: (3,) tuple, the base frame's origin in the world (m).
        rotation: (9,) tuple, the rotation from the base frame to the world, row by row.
        gravity: (3,) tuple, the gravity vector in the world (m/s^2); ``None``: the model's own.
    """

    position: tuple[float, ...] = (0.0, 0.0, 0.0)
    rotation: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    gravity: tuple[float, ...] | None = None

    def placement(self) -> pin.SE3:
        """The base frame in the world as a Pinocchio ``SE3``."""
        return pin.SE3(np.array(self.rotation, dtype=float).reshape(3, 3), np.array(self.position, dtype=float))


def _shown(value: object) -> str:
    """A number as a request gave it (``1200``, not numpy's ``np.float64(1200.0)``); anything
    else as its repr."""
    return f"{float(value):g}" if isinstance(value, int | float | np.number) and not isinstance(value, bool) else repr(value)


def _vector(values, field: str, accepted: Range, length: int = 3, signed: bool = True) -> tuple[float, ...]:
    """``values`` as a tuple of ``length`` finite floats, each within ``accepted`` (by magnitude
    when ``signed``)."""
    array = np.asarray(values, dtype=float).ravel()
    if array.shape != (length,):
        raise InvalidEquipment(f"{field} needs {length} numbers, got {array.size}", field)
    for index, value in enumerate(array):
        inside = accepted.holds_signed(value) if signed else accepted.holds(value)
        if not (math.isfinite(value) and inside):
            shown = f"[-{accepted.high:g}, {accepted.high:g}] {accepted.unit}" if signed else accepted.describe()
            raise InvalidEquipment(f"{field}[{index}] = {_shown(value)} is outside the accepted range {shown}", field)
    return tuple(float(value) for value in array)


def inertia_matrix(values: ArrayLike) -> np.ndarray:
    """The (3, 3) rotational inertia (kg m^2) from 9 values (a matrix, row by row) or 6 values
    [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]. A physical inertia is symmetric, positive definite, and its
    principal moments satisfy the triangle inequality (each at most the sum of the other two).

    Raises:
        InvalidEquipment: any of these fails, or an entry lies outside ``PAYLOAD_INERTIA``.
    """
    array = np.asarray(values, dtype=float).ravel()
    if array.size == 6:
        xx, yy, zz, xy, xz, yz = array
        array = np.array([xx, xy, xz, xy, yy, yz, xz, yz, zz])
    if array.size != 9:
        raise InvalidEquipment(f"inertia needs 6 values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix, got {array.size}", "inertia")
    matrix = np.array(_vector(array, "inertia", PAYLOAD_INERTIA, 9)).reshape(3, 3)
    if np.any(np.diag(matrix) < 0.0) or np.abs(matrix - matrix.T).max() > 1e-9 * max(1.0, np.abs(matrix).max()):
        raise InvalidEquipment("inertia must be symmetric with non-negative moments on its diagonal", "inertia")
    moments = np.linalg.eigvalsh(matrix)
    scale = max(float(moments.max()), 1e-300)
    if moments.min() <= 1e-12 * scale:
        raise InvalidEquipment(
            f"inertia is not positive definite (principal moments {', '.join(f'{m:.4g}' for m in moments)} kg m^2); "
            "leave it out for a point mass", "inertia"
        )
    if moments[2] > moments[0] + moments[1] + 1e-9 * scale:
        raise InvalidEquipment(
            f"inertia's principal moments {', '.join(f'{m:.4g}' for m in moments)} kg m^2 break the triangle inequality "
            "(the largest exceeds the sum of the other two): no rigid body has them", "inertia"
        )
    return matrix


def payload(
    mass: float, center_of_mass: ArrayLike = (0.0, 0.0, 0.0), inertia: ArrayLike | None = None, frame: str | None = None,
    radius: float = 0.0,
) -> Payload:
    """A checked ``Payload``: ``mass`` in ``PAYLOAD_MASS``, each coordinate of
    ``center_of_mass`` (3,) in ``CENTER_OF_MASS``, ``inertia`` as ``inertia_matrix`` reads it
    (``None``: a point mass), the collision sphere's ``radius`` in ``PAYLOAD_RADIUS``.

    Raises:
        InvalidEquipment: a quantity out of its range or not physical.
    """
    if not (isinstance(mass, int | float) and math.isfinite(mass) and PAYLOAD_MASS.holds(mass)):
        raise InvalidEquipment(f"mass = {_shown(mass)} is outside the accepted range {PAYLOAD_MASS.describe()}", "mass")
    if not (isinstance(radius, int | float) and math.isfinite(radius) and PAYLOAD_RADIUS.holds(radius)):
        raise InvalidEquipment(f"radius = {_shown(radius)} is outside the accepted range {PAYLOAD_RADIUS.describe()}", "radius")
    matrix = np.zeros((3, 3)) if inertia is None else inertia_matrix(inertia)
    center = _vector(center_of_mass, "center_of_mass", CENTER_OF_MASS)
    return Payload(float(mass), center, tuple(matrix.ravel().tolist()), frame, float(radius))


def rotation_matrix(rotation: ArrayLike | None = None, orientation: ArrayLike | None = None) -> np.ndarray:
    """The (3, 3) rotation from a matrix (3x3, orthonormal within ``ROTATION_TOLERANCE``,
    determinant +1) or a unit quaternion [qx, qy, qz, qw] (norm 1 within
    ``QUATERNION_TOLERANCE``); identity when neither is given. The result is made exactly
    orthonormal (the polar factor, by SVD).

    Raises:
        InvalidEquipment: both are given, or the one given is not a rotation.
    """
    if rotation is not None and orientation is not None:
        raise InvalidEquipment("give the base's rotation either as a rotation matrix or as a quaternion, not both", "rotation")
    if orientation is not None:
        quaternion = np.asarray(orientation, dtype=float).ravel()
        if quaternion.shape != (4,) or not np.isfinite(quaternion).all():
            raise InvalidEquipment("orientation must be 4 finite numbers [qx, qy, qz, qw]", "orientation")
        norm = float(np.linalg.norm(quaternion)) if np.abs(quaternion).max() <= 2.0 else math.inf
        if abs(norm - 1.0) > QUATERNION_TOLERANCE:
            shown = "above 2" if norm == math.inf else f"{norm:.6g}"
            raise InvalidEquipment(
                f"orientation has norm {shown}: not a rotation; give a unit quaternion [qx, qy, qz, qw] "
                f"(norm 1 within {QUATERNION_TOLERANCE:g})", "orientation"
            )
        x, y, z, w = quaternion / norm
        return pin.Quaternion(w, x, y, z).toRotationMatrix()
    if rotation is None:
        return np.eye(3)
    matrix = np.asarray(rotation, dtype=float)
    if matrix.size != 9 or not np.isfinite(matrix).all():
        raise InvalidEquipment("rotation must be a 3x3 matrix of finite numbers", "rotation")
    matrix = matrix.reshape(3, 3)
    error = float(np.abs(matrix.T @ matrix - np.eye(3)).max()) if np.abs(matrix).max() <= 2.0 else math.inf
    if error > ROTATION_TOLERANCE or np.linalg.det(matrix) <= 0.0:
        why = (
            "an entry exceeds 1 in magnitude" if error == math.inf
            else f"R^T R differs from the identity by {error:.3g}" if error > ROTATION_TOLERANCE
            else "its determinant is -1 (a reflection)"
        )
        raise InvalidEquipment(
            f"rotation is not a rotation matrix: {why}; give an orthonormal matrix with determinant +1 "
            f"(R^T R = I within {ROTATION_TOLERANCE:g}; [[-1,0,0],[0,-1,0],[0,0,1]] turns the base half a turn about z), "
            "or a unit quaternion", "rotation"
        )
    u, _, vt = np.linalg.svd(matrix)
    return u @ vt


def mounting(
    position: ArrayLike = (0.0, 0.0, 0.0), rotation: ArrayLike | None = None, orientation: ArrayLike | None = None,
    gravity: ArrayLike | None = None,
) -> Mounting:
    """A checked ``Mounting``: ``position`` (3,) within ``BASE_POSITION``, the rotation as
    ``rotation_matrix`` reads it, ``gravity`` (3,) within ``GRAVITY`` (``None``: the model's).

    Raises:
        InvalidEquipment: a quantity out of its range or not a rotation.
    """
    matrix = rotation_matrix(rotation, orientation)
    return Mounting(
        _vector(position, "position", BASE_POSITION),
        tuple(matrix.ravel().tolist()),
        None if gravity is None else _vector(gravity, "gravity", GRAVITY),
    )


_lock = threading.Lock()
_equipped: OrderedDict[tuple, tuple[Robot, Robot]] = OrderedDict()


def equip(robot: Robot, payload: Payload | None = None, mounting: Mounting | None = None) -> Robot:
    """``robot`` carrying ``payload`` (default: the one it carries already, as an upload's
    default) and mounted by ``mounting`` (default: its own). The variant is built from the bare
    robot once and cached (``CACHE_SIZE`` most recent); a payload of mass 0 without a collision
    sphere is none.

    Raises:
        InvalidEquipment: the payload's frame is not a frame of the robot.
    """
    bare = robot.bare or robot
    payload = payload if payload is not None else robot.payload
    mounting = mounting if mounting is not None else robot.mounting
    if payload is not None and payload.mass == 0.0 and payload.radius == 0.0:
        payload = None
    if payload == robot.payload and mounting == robot.mounting:
        return robot
    if payload is None and mounting is None:
        return bare
    key = (id(bare), payload, mounting)
    with _lock:
        held = _equipped.get(key)
        if held is not None and held[0] is bare:
            _equipped.move_to_end(key)
            return held[1]
    made = _build(bare, payload, mounting)
    with _lock:
        _equipped[key] = (bare, made)
        while len(_equipped) > CACHE_SIZE:
            _equipped.popitem(last=False)
    return made


def _build(bare: Robot, payload: Payload | None, mounting: Mounting | None) -> Robot:
    """A new ``Robot`` on a copy of ``bare``'s model with ``payload`` added and ``mounting`` applied."""
    model = pin.Model(bare.model)
    notes = list(bare.notes)
    if payload is not None:
        frame_name = payload.frame or bare.end_effector
        if not model.existFrame(frame_name):
            frames = [item.name for item in model.frames if item.name != "universe"]
            shown = ", ".join(repr(item) for item in frames[:60]) + (", ..." if len(frames) > 60 else "")
            raise InvalidEquipment(f"the payload's frame {frame_name[:100]!r} is not a frame of {bare.name}; its frames are {shown}", "frame")
        frame = model.frames[frame_index(model, frame_name)]
        body = pin.Inertia(payload.mass, np.array(payload.center_of_mass), np.array(payload.inertia).reshape(3, 3))
        model.appendBodyToJoint(frame.parentJoint, body, frame.placement)
        notes.append(f"payload of {payload.mass:g} kg at {frame_name}")
    if mounting is not None:
        base = mounting.placement()
        for joint in range(1, model.njoints):
            if model.parents[joint] == 0:
                model.jointPlacements[joint] = base * model.jointPlacements[joint]
        for frame in list(model.frames)[1:]:  # the first frame is the world itself
            if frame.parentJoint == 0:
                frame.placement = base * frame.placement
        if mounting.gravity is not None:
            model.gravity = pin.Motion(np.array(mounting.gravity), np.zeros(3))
    made = Robot.from_model(
        bare.name, model, bare.source, bare.end_effector, bare.limits, bare.limit_sources, bare.locked_joints,
        tuple(notes), payload=payload, mounting=mounting, bare=bare,
    )
    # The links allowed to touch (an upload's option) are the same links, wherever the base is.
    return dataclasses.replace(made, allowed_collisions=bare.allowed_collisions)
