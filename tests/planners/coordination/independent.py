"""Independent checks of a cell's motion: the arms' distance by coal (capsule to capsule, from
Pinocchio's forward kinematics of each sample), and limits from the samples."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from toptraj.robots.collision import robot_capsules


def _coal_capsules(arm, q: np.ndarray) -> list[tuple[coal.Capsule, coal.Transform3s]]:
    """The arm's capsules at joint positions ``q`` (n_dof,) as coal shapes placed in the world:
    the bare robot's kinematics, then its base pose applied here."""
    robot = arm.robot.bare or arm.robot
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, robot.configuration(q[None])[0])
    placed = []
    for capsule in robot_capsules(robot):
        pose = data.oMi[capsule.joint]  # the base's own capsules at joint 0: the universe
        a = arm.base_rotation @ (pose.rotation @ capsule.a + pose.translation) + arm.base_position
        b = arm.base_rotation @ (pose.rotation @ capsule.b + pose.translation) + arm.base_position
        axis = b - a
        length = float(np.linalg.norm(axis))
        z = axis / length if length > 0 else np.array([0.0, 0.0, 1.0])
        rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), z).matrix()
        placed.append((coal.Capsule(capsule.radius, length), coal.Transform3s(rotation, (a + b) / 2.0)))
    return placed


def coal_distance(cell, q_first: np.ndarray, q_second: np.ndarray) -> float:
    """Smallest coal distance (m) between the two arms' capsules at one pair of configurations."""
    request, best = coal.DistanceRequest(), np.inf
    for shape_a, pose_a in _coal_capsules(cell.arms[0], q_first):
        for shape_b, pose_b in _coal_capsules(cell.arms[1], q_second):
            result = coal.DistanceResult()
            best = min(best, coal.distance(shape_a, pose_a, shape_b, pose_b, request, result))
    return float(best)
