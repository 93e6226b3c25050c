"""Imported by the fork server of ``toptraj.planners.execution.isolated`` (its ``PRELOAD``): a ur5
path timed by phase_plane through the runner (the limit gate, the answer's utilization, torques
and conditioning), as a search's answer is timed in its worker, so that those compiled kernels
are in the fork server's memory and in every worker forked from it instead of each worker
loading them from numba's disk cache (``toptraj.planners.generators.search.warm`` does the same
for the search itself). A failure is logged and skipped: a warm-up only saves time.
"""

from __future__ import annotations

import logging

import numpy as np

from toptraj import robots
from toptraj.planners.problem.build import build_problem
from toptraj.planners.problem.problem import LimitRequest
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.runner.run import run
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

log = logging.getLogger(__name__)


def warm() -> None:
    """A ur5 path of three waypoints timed under velocity, acceleration and torque limits,
    computed and dropped; a failure is logged."""
    try:
        robot = robots.load("ur5")
        waypoints = np.array([[-1.0, -1.2, 1.5, -1.9, -1.57, 0.0], [0.1, -1.1, 1.6, -1.8, -1.47, 0.1], [1.0, -1.2, 1.5, -1.9, -1.57, 0.0]])
        run(build_problem(robot, WaypointPath(waypoints), PhasePlaneMethod(), limits=LimitRequest(kinds=("velocity", "acceleration", "torque"))))
    except Exception:
        log.warning("the runner's warm-up failed; its kernels load in each worker instead", exc_info=True)


warm()
