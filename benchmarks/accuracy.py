"""Duration accuracy of the default answer: each method's duration over the converged
time-optimal duration (TOPP-RA through toptraj's adapter on 20,000 intervals, the grid the
service allows at most), on seeded random spline paths.

    python benchmarks/accuracy.py --robots ur5,panda,geering_2r,yamamoto_2r --paths 15

Prints one line per robot and method: the number of paths, and the max, median and min ratio.
"""

from __future__ import annotations

import argparse

import numpy as np

import robots
from planners import Timing, WaypointPath, plan
from planners.constraints import build_path_constraints
from planners.errors import InfeasiblePath
from planners.grid import MAX_POINTS, path_grid
from planners.paths import SplinePath
from planners.timing.toppra_method import ToppraMethod

KINDS = ("velocity", "acceleration", "torque")


def random_waypoints(robot, rng) -> np.ndarray:
    """2 to 5 waypoints within the middle 70 % of each joint's range (+-pi for continuous ones)."""
    lower = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.35 * (upper - lower)
    return middle + rng.uniform(-1, 1, (int(rng.integers(2, 6)), robot.dof)) * half


def converged_duration(robot, waypoints) -> float:
    path = SplinePath(waypoints)
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, MAX_POINTS))
    return ToppraMethod().solve(constraints).duration


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="ur5,panda,geering_2r,yamamoto_2r")
    parser.add_argument("--methods", default="phase_plane,toppra,min_cost")
    parser.add_argument("--paths", type=int, default=15)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    methods = args.methods.split(",")
    for name in args.robots.split(","):
        robot = robots.load(name)
        rng = np.random.default_rng(args.seed)
        ratios = {method: [] for method in methods}
        refused = 0
        for _ in range(args.paths):
            waypoints = random_waypoints(robot, rng)
            try:
                reference = converged_duration(robot, waypoints)
            except InfeasiblePath:
                refused += 1  # no timing can follow this path (the same 422 for every method)
                continue
            for method in methods:
                result = plan(robot, WaypointPath(waypoints), Timing(method=method, constraints=KINDS), dt=0.01)
                ratios[method].append(result.duration / reference)
        if refused:
            print(f"{name:12s} {refused} of {args.paths} paths cannot be followed within the limits")
        for method, values in ratios.items():
            values = np.array(values)
            print(
                f"{name:12s} {method:12s} paths {len(values):3d}  duration / converged: max {values.max():.5f}  "
                f"median {np.median(values):.5f}  min {values.min():.5f}"
            )


if __name__ == "__main__":
    main()
