"""Cells of the coordination tests: two ur5 facing each other across a table (bases 1.2 m apart,
the second turned half a turn), each sweeping its arm across the shared middle."""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.coordination import Cell, CellArm
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.waypoints import make_path
from toptraj.robots.equipment import Payload, equip, mounting

FIRST = [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [0.0, -0.6, 0.6, 0.0, 0.3, 0.0], [-1.5, -0.5, 0.5, 0.0, 0.0, 0.0]]
SECOND = [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [0.0, -0.6, 0.6, 0.0, -0.3, 0.0], [-1.5, -0.5, 0.5, 0.0, 0.0, 0.0]]
TURNED = np.diag([-1.0, -1.0, 1.0])


def ur5_arm(waypoints, position, rotation=None, payload: Payload | None = None) -> CellArm:
    """A ur5 standing at ``position`` turned by ``rotation`` (default none), carrying ``payload``."""
    bare = robots.load("ur5")
    robot = equip(bare, payload, mounting(position, rotation))
    path = make_path(robot, WaypointPath(np.array(waypoints, dtype=float)))
    return CellArm(robot, path, robot.limits)


def facing_cell(distance: float = 1.2, clearance: float = 0.02) -> Cell:
    """The two ur5 facing each other ``distance`` m apart, with crossing paths."""
    return Cell((ur5_arm(FIRST, [0.0, 0.0, 0.0]), ur5_arm(SECOND, [distance, 0.0, 0.0], TURNED)), clearance)
