"""Seeded random spline paths and their converged time-optimal durations, the references of
``phase_plane_vs_toppra.py``.

A path: 2 to 5 waypoints within the middle 70 % of each joint's range, the natural cubic spline
through them inside the joint limits. Its converged duration T* (s) under velocity,
acceleration and torque limits is the Richardson extrapolation 2 T(2N) - T(N) of the
conservative (interpolation) discretization of ``PhasePlaneMethod``, first order in the
interval length, from N = 10,000 intervals and every interval then halved; it must agree with
the midpoint (second-order) discretization on the 2N intervals within ``CONVERGED`` (else the
same on 20,000 and 40,000 intervals).
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.paths import SplinePath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing import PhasePlaneMethod
from toptraj.planners.timing.phase_plane.method import midpoint_duration

KINDS = ("velocity", "acceleration", "torque")
#: Largest disagreement of the two estimates of the converged duration.
CONVERGED = 1e-5


def random_path(robot, rng) -> tuple[np.ndarray, SplinePath]:
    """2 to 5 waypoints within the middle 70 % of each joint's range (+-pi for continuous joints),
    drawn until the spline through them stays within the joint limits."""
    lower = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.35 * (upper - lower)
    while True:
        waypoints = middle + rng.uniform(-1, 1, (int(rng.integers(2, 6)), robot.dof)) * half
        path = SplinePath(waypoints)
        q = path(np.linspace(0.0, 1.0, 1000))
        if np.all(q >= robot.limits.position_lower) and np.all(q <= robot.limits.position_upper):
            return waypoints, path


def _halved(grid: np.ndarray) -> np.ndarray:
    """``grid`` with every interval split in two."""
    fine = np.empty(2 * len(grid) - 1)
    fine[0::2] = grid
    fine[1::2] = 0.5 * (grid[:-1] + grid[1:])
    return fine


def converged_duration(path, robot, limits=None, kinds=KINDS) -> tuple[float, float]:
    """T* and its relative gap to the midpoint estimate (see the module docstring): on 10,000
    and 20,000 intervals, or on 20,000 and 40,000 where those two disagree by more than
    CONVERGED; under ``limits`` (default the robot's) of ``kinds``."""
    limits = robot.limits if limits is None else limits
    unrefined = PhasePlaneMethod(max_refinements=0)
    coarse_grid = path_grid(path, 10_000)
    coarse = unrefined.solve(build_path_constraints(path, robot, limits, kinds, coarse_grid)).duration
    for _ in range(2):
        fine_grid = _halved(coarse_grid)
        constraints = build_path_constraints(path, robot, limits, kinds, fine_grid)
        fine = unrefined.solve(constraints).duration
        richardson = 2.0 * fine - coarse
        gap = abs(midpoint_duration(constraints) / richardson - 1.0)
        if gap <= CONVERGED:
            break
        coarse_grid, coarse = fine_grid, fine
    return richardson, gap
