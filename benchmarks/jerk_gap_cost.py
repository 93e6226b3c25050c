"""The time ``jerk_limited``'s gap estimate costs (``toptraj.planners.timing.jerk.stated_gap``):
the method's solve with the estimate against the same solve stating only the difference from
its second grid (the statement before it), interleaved, on the spline paths of the invariant
test (4 waypoints in the middle 30 % of each joint's range, seed 16) of ur5 (jerk limits at every
joint) and yamamoto_2r (no jerk limit: its ends at rest are halved twice for the estimate), on
the default grid and on named grids of 100, 200 and 400 intervals. Prints, per case, the median
times over ``--repeats`` rounds and their ratio, with the gaps stated either way.

    python benchmarks/jerk_gap_cost.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from toptraj import robots
from toptraj.planners import WaypointPath
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.timing.jerk import method as jerk_method
from toptraj.planners.timing.jerk.accuracy import relative_gap
from toptraj.planners.timing.jerk.method import JerkLimitedMethod

KINDS = ("velocity", "acceleration", "torque", "jerk")
ESTIMATED = jerk_method.stated_gap


def _difference_only(solve, affordable, constraints, boundary, answer, chain, unfilled, how):
    """The statement before the estimate: the difference over the last two grids."""
    return relative_gap(chain[-2], chain[-1]), how


def _constraints(name: str, intervals: int | None):
    robot = robots.load(name)
    limits = robot.limits
    lower = np.where(np.isfinite(limits.position_lower), limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(limits.position_upper), limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.15 * (upper - lower)
    waypoints = middle + np.random.default_rng(16).uniform(-1.0, 1.0, (4, len(lower))) * half
    path = make_path(robot, WaypointPath(waypoints, "spline"))
    return build_path_constraints(path, robot, limits, KINDS, path_grid(path, intervals))


def _timed(constraints, estimate) -> tuple[float, float]:
    jerk_method.stated_gap = estimate
    try:
        started = time.perf_counter()
        result = JerkLimitedMethod().solve(constraints)
        return time.perf_counter() - started, float(result.optimality_gap)
    finally:
        jerk_method.stated_gap = ESTIMATED


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"{'case':<22} {'before s':>9} {'with s':>9} {'ratio':>6} {'gap before':>11} {'gap now':>9}")
    for name in ("ur5", "yamamoto_2r"):
        for intervals in (None, 100, 200, 400):
            constraints = _constraints(name, intervals)
            _timed(constraints, ESTIMATED)  # compiles and warms both
            before, after, gaps = [], [], {}
            for _ in range(args.repeats):
                for estimate, times in ((_difference_only, before), (ESTIMATED, after)):
                    seconds, gaps[estimate] = _timed(constraints, estimate)
                    times.append(seconds)
            b, a = float(np.median(before)), float(np.median(after))
            label = f"{name} {'default' if intervals is None else intervals}"
            print(f"{label:<22} {b:9.3f} {a:9.3f} {a / b:6.2f} {gaps[_difference_only]:11.2e} {gaps[ESTIMATED]:9.2e}")


if __name__ == "__main__":
    main()
