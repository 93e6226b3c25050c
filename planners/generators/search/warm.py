"""Imported by the fork server of ``toptraj.planners.execution.isolated`` (its ``PRELOAD``): a small
search on the two-link Geering arm around a sphere (an 8-cell lattice) and a short local
optimization of its grid path, then a small roadmap search on ur5 (its velocity, acceleration
and torque rows, its links kept apart), so that the compiled kernels of the search (free space,
bounds, branch and bound) and of the local optimization (its objective, the exact timing, the
clearance checks) are in the fork server's memory and in every search's worker forked from it.

A numba kernel compiled with ``cache=True`` loads its machine code from the on-disk cache at its
first call in a process: the local optimization's objective alone takes 0.3 to 0.9 s to load
in each worker, paid once here instead (as ``collocation.warm`` does for the collocation). The
kernels take one signature for every arm (two joints or seven, obstacles or none, friction or
none: ``tests/planners/generators/test_search_warm.py``).

A warm-up only saves time: a step that fails is logged and skipped, since the fork server
imports this module and would otherwise stop, failing every later isolated call.
"""

from __future__ import annotations

import logging

import numpy as np

from toptraj import robots
from toptraj.planners.collision import BoxObstacle, SphereObstacle
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.local import optimize_locally
from toptraj.planners.generators.search.local_outcome import LocalSettings
from toptraj.planners.generators.search.method import global_search

log = logging.getLogger(__name__)


def warm() -> None:
    """The small searches and local optimization (module docstring), computed and dropped; a
    step that raises is logged."""
    for step in (_lattice, _roadmap):
        try:
            step()
        except Exception:
            log.warning("the search's warm-up step %s failed; its kernels load in each worker instead", step.__name__, exc_info=True)


def _lattice() -> None:
    robot = robots.load("geering_2r")
    sphere = (SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05),)
    found = global_search(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), SearchOptions(cells=(8,), tubes=1), True, sphere, 0.01)
    settings = LocalSettings(max_control_points=5, evaluations_per_variable=2)
    optimize_locally(robot, found.result.tubes[0].points, robot.limits, ("torque",), sphere, 0.01, settings=settings)


def _roadmap() -> None:
    robot, kinds = robots.load("ur5"), ("velocity", "acceleration", "torque")
    start, goal = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    box = (BoxObstacle(np.array([2.0, 2.0, 2.0]), np.array([0.15, 0.15, 0.15])),)  # out of reach: a grid path always
    global_search(robot, robot.limits, kinds, start, goal, SearchOptions(roadmap_points=4, neighbors=2, tubes=1), True, box, 0.02)


warm()
