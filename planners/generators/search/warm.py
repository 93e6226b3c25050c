"""Imported by the fork server of ``toptraj.planners.execution.isolated`` (its ``PRELOAD``): a small
search on the two-link Geering arm around a sphere (an 8-cell lattice) and a short local
optimization of its grid path, so that the compiled kernels of the search (free space, bounds,
branch and bound) and of the local optimization (its objective, the exact timing, the clearance
checks) are in the fork server's memory and in every search's worker forked from it.

A numba kernel compiled with ``cache=True`` loads its machine code from the on-disk cache at its
first call in a process: the local optimization's objective alone takes 0.3 to 0.9 s to load
in each worker, paid once here instead (as ``collocation.warm`` does for the collocation). The
objective's kernel takes one signature for every arm (two joints or seven, obstacles or none,
friction or none: ``tests/service/test_warmup_search.py``).
"""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.collision import SphereObstacle
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.local import optimize_locally
from toptraj.planners.generators.search.local_outcome import LocalSettings
from toptraj.planners.generators.search.method import global_search


def warm() -> None:
    """A small search and two rounds' worth of local optimization, computed and dropped."""
    robot = robots.load("geering_2r")
    sphere = (SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05),)
    found = global_search(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), SearchOptions(cells=(8,), tubes=1), True, sphere, 0.01)
    settings = LocalSettings(max_control_points=5, evaluations_per_variable=2)
    optimize_locally(robot, found.result.tubes[0].points, robot.limits, ("torque",), sphere, 0.01, settings=settings)


warm()
