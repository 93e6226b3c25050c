"""Imported by the fork server of ``toptraj.planners.execution.isolated`` (its ``PRELOAD``): the
collocation's first guess (``collocation._timed_guess``: a spline, its constraint rows, the
phase-plane solve and its sampling) computed once on the two-link Geering arm, so that the
compiled kernels it calls are in the fork server's memory and in every worker forked from it.

A numba kernel compiled with ``cache=True`` loads its machine code from the on-disk cache at its
first call in a process: 0.36 s in each worker that optimizes a ur5 free motion, about as long
as the optimization itself, paid once here instead. The kernels take arrays of any length and
any number of joints, so that one small problem loads the signatures every arm uses.
"""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.generators.collocation.collocation import _Problem, _timed_guess
from toptraj.planners.problem.free_motion import FreeMotion


def warm() -> None:
    """The first guess of a two-joint free motion, computed and dropped."""
    robot = robots.load("geering_2r")
    start, goal = np.zeros(robot.dof), np.full(robot.dof, 0.5)
    problem = _Problem(robot, robot.limits, FreeMotion(start, goal, intervals=4, revolutions=False), goal, 0.0)
    _timed_guess(problem, np.zeros(robot.dof))


warm()
