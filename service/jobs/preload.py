"""Imported by the fork server (``JOB_MODULES``) before it forks job workers: the job code and
the phase-plane kernels (compiled code that numba loads from its cache on first use, about half
a second), so that every worker starts with them ready instead of loading them again."""

from __future__ import annotations

import logging

import numpy as np

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, WaypointPath, build_problem, plan
from toptraj.service.jobs import work  # noqa: F401


def _warm_up() -> None:
    arm = robots.load("yamamoto_2r")
    path = WaypointPath(np.array([[0.0, 0.0], [0.1, 0.0]]))
    plan(build_problem(arm, path, METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",))))


try:
    _warm_up()
except Exception:  # a failed warm-up costs time only; it must not stop the fork server
    logging.getLogger("toptraj.jobs").exception("warming up the job workers failed")
