"""Cells of the coordination tests: two ur5 facing each other across a table (bases 1.2 m apart,
the second turned half a turn), each sweeping its arm across the shared middle."""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.coordination import Cell, CellArm
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.waypoints import make_path

FIRST = [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [0.0, -0.6, 0.6, 0.0, 0.3, 0.0], [-1.5, -0.5, 0.5, 0.0, 0.0, 0.0]]
SECOND = [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [0.0, -0.6, 0.6, 0.0, -0.3, 0.0], [-1.5, -0.5, 0.5, 0.0, 0.0, 0.0]]
TURNED = np.diag([-1.0, -1.0, 1.0])


def ur5_arm(waypoints, position, rotation=None) -> CellArm:
    robot = robots.load("ur5")
    path = make_path(robot, WaypointPath(np.array(waypoints, dtype=float)))
    rotation = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    return CellArm(robot, path, robot.limits, rotation, np.array(position, dtype=float))


def facing_cell(distance: float = 1.2, clearance: float = 0.02) -> Cell:
    """The two ur5 facing each other ``distance`` m apart, with crossing paths."""
    return Cell((ur5_arm(FIRST, [0.0, 0.0, 0.0]), ur5_arm(SECOND, [distance, 0.0, 0.0], TURNED)), clearance)
