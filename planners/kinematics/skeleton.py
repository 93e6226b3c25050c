"""The arm as a stick figure: the world positions of its joint origins and of its end
effector, for drawing stroboscopic pictures like Jeong & Lee's Figs. 1-4 (``000_…txt``).

Forward kinematics by Pinocchio (``forwardKinematics``, ``updateFramePlacement``): for each
configuration, ``oMi[j].translation`` of every joint j = 1 … njoints and the end effector's
frame placement.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from toptraj.robots import Robot


def skeleton(robot: Robot, q: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Point names (the joints, then the end effector) and their world positions for each
    configuration: ``q`` (n, n_dof) in rad or m; positions (n, n_joints + 1, 3) in m."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    model, data = robot.model, robot.data
    names = [model.names[j] for j in range(1, model.njoints)] + [robot.end_effector]
    tip = robot.frame_id(robot.end_effector)
    out = np.empty((len(q), len(names), 3))
    for row, configuration in enumerate(robot.configuration(q)):
        pin.forwardKinematics(model, data, configuration)
        for j in range(1, model.njoints):
            out[row, j - 1] = data.oMi[j].translation
        out[row, -1] = pin.updateFramePlacement(model, data, tip).translation
    return names, out
