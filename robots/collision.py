"""The robot's collision geometry, as one capsule per link: conservative and fast to measure.

A capsule is a segment [a, b] in the frame of the joint that moves it (Pinocchio joint index,
0 for the fixed base) and a radius: every point within ``radius`` of the segment belongs to it.

* Arms of example-robot-data ship collision meshes (ur5: 8 meshes of 230-600 vertices). Each
  mesh, placed in its joint's frame, is wrapped in the capsule along its principal axis that
  contains every vertex (``fit_capsule``): the segment spans the vertices' extreme projections on
  the axis and the radius is their largest distance to it, so the capsule contains the mesh's
  convex hull. Measured on ur5: a mesh-to-sphere distance query of coal cost 10.7 ms, a capsule
  to sphere distance below 1 µs in numpy over all capsules and states at once.
* Arms without collision geometry (the paper arms, uploads whose meshes are not available) get
  a capsule along each link, from its joint to the next joint (the last to the end effector),
  of radius ``LINK_RADIUS`` (0.03 m; the papers give none).

A payload with a collision ``radius`` (``toptraj.robots.equipment.Payload``) adds a sphere about
its centre of mass, held by the joint of its frame: obstacles, other arms and the robot's own
links are kept from it as from a link.

The links against each other (self-collision) are checked by
``toptraj.planners.collision.self_collision`` on the same capsules.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from toptraj.robots.robot import Robot

#: Radius (m) of the capsules of arms without collision geometry.
LINK_RADIUS = 0.03


@dataclass(frozen=True)
class LinkCapsule:
    """A capsule of a link: ``name``, the Pinocchio ``joint`` moving it (0: the fixed base), end
    points ``a``, ``b`` (3,) in that joint's frame (m), its ``radius`` (m), the ``link`` (URDF
    link name) it belongs to ("": not known) and whether it wraps a collision mesh (``mesh``;
    else a capsule along the link, of ``LINK_RADIUS``, or a payload's sphere)."""

    name: str
    joint: int
    a: np.ndarray
    b: np.ndarray
    radius: float
    link: str = ""
    mesh: bool = False


def fit_capsule(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """The capsule along the principal axis of ``points`` (k, 3) that contains them all:
    end points a, b (3,) and radius (m)."""
    points = np.asarray(points, dtype=float)
    center = points.mean(axis=0)
    _, _, axes = np.linalg.svd(points - center, full_matrices=False)
    axis = axes[0]
    along = (points - center) @ axis
    a, b = center + along.min() * axis, center + along.max() * axis
    return a, b, float(np.max(_point_segment_distance(points, a, b)))


def _point_segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    length2 = float(ab @ ab)
    t = np.zeros(len(points)) if length2 == 0.0 else np.clip((points - a) @ ab / length2, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def _shape_points(geometry) -> np.ndarray | None:
    """Points whose capsule contains the coal shape ``geometry`` (its frame), or None when its
    kind is not handled."""
    import coal

    if isinstance(geometry, coal.BVHModelBase):
        return np.asarray(geometry.vertices(), dtype=float)
    if isinstance(geometry, coal.Box):
        half = np.asarray(geometry.halfSide, dtype=float)
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    if isinstance(geometry, coal.Sphere):
        r = geometry.radius
        return np.vstack([np.eye(3) * r, -np.eye(3) * r])
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        r, h = geometry.radius, geometry.halfLength
        extra = r if isinstance(geometry, coal.Capsule) else 0.0
        # a circle of radius r is inside the capsule through its 8-gon of radius r / cos(pi/8)
        angles = np.linspace(0.0, 2.0 * np.pi, 8, endpoint=False)
        ring = np.column_stack([np.cos(angles), np.sin(angles)]) * (r / np.cos(np.pi / 8))
        ends = [np.column_stack([ring, np.full(8, z)]) for z in (-h - extra, h + extra)]
        return np.vstack(ends)
    return None


def capsules_from_geometry(model: pin.Model, geometry_model: pin.GeometryModel) -> list[LinkCapsule]:
    """One capsule per geometry object with a shape ``_shape_points`` handles, in its parent
    joint's frame."""
    capsules = []
    for item in geometry_model.geometryObjects:
        points = _shape_points(item.geometry)
        if points is None or len(points) == 0:
            continue
        placed = points @ item.placement.rotation.T + item.placement.translation
        a, b, radius = fit_capsule(placed)
        link = model.frames[item.parentFrame].name if item.parentFrame < len(model.frames) else item.name
        capsules.append(LinkCapsule(item.name, int(item.parentJoint), a, b, radius, link, mesh=True))
    return capsules


def skeleton_capsules(model: pin.Model, end_effector_frame: int, radius: float = LINK_RADIUS) -> list[LinkCapsule]:
    """A capsule from each joint to its child joint, and from the last joint to the end
    effector, of ``radius``."""
    capsules = []
    for child in range(1, model.njoints):
        parent = model.parents[child]
        if parent == 0:
            continue
        end = np.array(model.jointPlacements[child].translation)
        capsules.append(LinkCapsule(model.names[parent], parent, np.zeros(3), end, radius, _body_of(model, parent)))
    frame = model.frames[end_effector_frame]
    tip = np.array(frame.placement.translation)
    joint = int(frame.parentJoint)
    capsules.append(LinkCapsule(model.names[joint], joint, np.zeros(3), tip, radius, _body_of(model, joint)))
    return capsules


def _body_of(model: pin.Model, joint: int) -> str:
    """The name of the link (first body frame) that ``joint`` moves; the joint's name if none."""
    for frame in model.frames:
        if frame.type == pin.FrameType.BODY and frame.parentJoint == joint:
            return frame.name
    return model.names[joint]


def world_capsules(model: pin.Model, data: pin.Data, capsules: list[LinkCapsule], configurations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World end points of every capsule in each configuration: a, b of shape (n, k, 3), for
    Pinocchio configurations (n, nq)."""
    n = len(configurations)
    a = np.empty((n, len(capsules), 3))
    b = np.empty((n, len(capsules), 3))
    local_a = np.array([c.a for c in capsules])
    local_b = np.array([c.b for c in capsules])
    joints = [int(c.joint) for c in capsules]
    for row, configuration in enumerate(configurations):
        pin.forwardKinematics(model, data, configuration)
        rotations = np.array([data.oMi[j].rotation for j in joints])
        translations = np.array([data.oMi[j].translation for j in joints])
        a[row] = np.einsum("kij,kj->ki", rotations, local_a) + translations
        b[row] = np.einsum("kij,kj->ki", rotations, local_b) + translations
    return a, b


def _example_arm_capsules(name: str) -> list[LinkCapsule] | None:
    """Capsules of example-robot-data's arm ``name`` from its collision meshes, in the joints
    of the catalog's model (reduced where the catalog locks joints); None without meshes."""
    from toptraj.robots.catalog import EXAMPLE_ARMS, example_urdf_path

    arm = EXAMPLE_ARMS[name]
    path = example_urdf_path(arm.loader)
    share = path.split("/example-robot-data/")[0]
    model = pin.buildModelFromUrdf(path)
    try:
        geometry = pin.buildGeomFromUrdf(model, path, pin.COLLISION, package_dirs=[share])
    except ValueError:  # a mesh that cannot be found
        return None
    if arm.locked:
        reference = pin.neutral(model)
        for joint_name, value in arm.locked.items():
            reference[model.joints[model.getJointId(joint_name)].idx_q] = value
        locked = [model.getJointId(joint_name) for joint_name in arm.locked]
        model, geometry = pin.buildReducedModel(model, geometry, locked, reference)
    capsules = capsules_from_geometry(model, geometry)
    return capsules or None


_CATALOG_CAPSULES: dict[str, list[LinkCapsule]] = {}


def robot_capsules(robot: Robot) -> list[LinkCapsule]:
    """The capsules of ``robot`` (a ``robots.Robot``), built once per catalog robot: from the
    collision meshes of example-robot-data's arms, else along the links (``LINK_RADIUS``); those
    of the fixed base placed by the robot's mounting."""
    cached = _CATALOG_CAPSULES.get(robot.name) if robot.source != "upload" else None
    if cached is not None:
        return _mounted(cached, robot.mounting) + _payload_capsules(robot)
    capsules = _example_arm_capsules(robot.name) if robot.source == "example-robot-data" else None
    if capsules is None:
        capsules = skeleton_capsules(robot.model, robot.frame_id(robot.end_effector))
    if robot.source != "upload":
        _CATALOG_CAPSULES[robot.name] = capsules
    return _mounted(capsules, robot.mounting) + _payload_capsules(robot)


def _payload_capsules(robot) -> list[LinkCapsule]:
    """The payload's collision sphere (``Payload.radius`` > 0) about its centre of mass, as a
    capsule of zero length in the frame of the joint holding it; the link is named "payload"."""
    payload = robot.payload
    if payload is None or payload.radius <= 0.0:
        return []
    frame = robot.model.frames[robot.frame_id(payload.frame or robot.end_effector)]
    center = frame.placement.act(np.array(payload.center_of_mass, dtype=float))
    return [LinkCapsule("payload", int(frame.parentJoint), center, center.copy(), float(payload.radius), "payload")]


def _mounted(capsules: list[LinkCapsule], mounting) -> list[LinkCapsule]:
    """``capsules`` with those of the fixed base (joint 0, the world) moved by the base pose of
    ``mounting`` (a ``toptraj.robots.equipment.Mounting``; ``None``: as they are)."""
    if mounting is None:
        return capsules
    rotation = np.array(mounting.rotation, dtype=float).reshape(3, 3)
    position = np.array(mounting.position, dtype=float)
    return [
        LinkCapsule(c.name, 0, rotation @ c.a + position, rotation @ c.b + position, c.radius, c.link) if c.joint == 0 else c
        for c in capsules
    ]
