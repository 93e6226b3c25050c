"""Inverse kinematics by damped least squares (Pinocchio frame Jacobians), continued along a
sequence of targets so that each solution seeds the next (the lecture's Cartesian-space
procedure: divide the line into small segments and solve the inverse kinematics at each).

Tasks are either positions only (3 rows, orientation free) or full poses (6 rows, the error
being log3 of the rotation error in the world frame and the position error).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from toptraj.robots import Robot

#: Damping of the least-squares step (in the units of the task, m or rad).
DAMPING = 1e-4
#: Convergence threshold on the task error (m, rad).
TOLERANCE = 1e-10
MAX_ITERATIONS = 60


@dataclass(frozen=True)
class IKResult:
    """Joint solution, the remaining task error (norm, m/rad), and the smallest singular value
    of the task Jacobian there (m/rad per rad: near 0 at a singularity)."""

    q: np.ndarray
    error: float
    sigma_min: float


def frame_pose(robot: Robot, q: np.ndarray, frame_id: int) -> pin.SE3:
    """Placement of frame ``frame_id`` in the world at joint coordinates ``q``."""
    data = robot.data
    pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
    return data.oMf[frame_id].copy()


def _task(robot: Robot, q, frame_id, target_position, target_rotation):
    data = robot.data
    configuration = robot.configuration(q)
    pin.computeJointJacobians(robot.model, data, configuration)
    pin.updateFramePlacements(robot.model, data)
    placement = data.oMf[frame_id]
    jacobian = pin.getFrameJacobian(robot.model, data, frame_id, pin.LOCAL_WORLD_ALIGNED)
    position_error = target_position - placement.translation
    if target_rotation is None:
        return position_error, jacobian[:3]
    rotation_error = pin.log3(target_rotation @ placement.rotation.T)
    return np.concatenate([position_error, rotation_error]), jacobian


def solve_ik(
    robot: Robot,
    q_seed: np.ndarray,
    frame_id: int,
    target_position: np.ndarray,
    target_rotation: np.ndarray | None = None,
) -> IKResult:
    """Damped least squares from ``q_seed`` to the target, joint limits enforced by clamping."""
    lower, upper = robot.limits.position_lower, robot.limits.position_upper
    q = np.clip(np.asarray(q_seed, dtype=float).copy(), lower, upper)
    error_norm = np.inf
    for _ in range(MAX_ITERATIONS):
        error, jacobian = _task(robot, q, frame_id, target_position, target_rotation)
        error_norm = float(np.linalg.norm(error))
        if error_norm < TOLERANCE:
            break
        step = jacobian.T @ np.linalg.solve(jacobian @ jacobian.T + DAMPING**2 * np.eye(len(error)), error)
        q = np.clip(q + step, lower, upper)
    _, jacobian = _task(robot, q, frame_id, target_position, target_rotation)
    singular_values = np.linalg.svd(jacobian, compute_uv=False)
    rank = min(jacobian.shape)
    return IKResult(q=q, error=error_norm, sigma_min=float(singular_values[:rank].min()))
