"""Solve time of ``phase_plane`` against ``toppra`` at equal accuracy, in one run.

For seeded random spline paths on ur5 and panda (velocity + acceleration + torque), the
reference duration is TOPP-RA's on a 10,000-interval grid. For each method, the smallest grid of
a ladder whose duration lies within 0.1 % of the reference is found; the method's solve time on
that grid (best of 3, PathConstraints built beforehand and shared) is recorded, and so is the
time to build those constraints. Prints the median and p95 of the time ratio toppra / phase_plane
(> 1: phase_plane is faster), and the paths where phase_plane is slower.

    python benchmarks/phase_plane_vs_toppra.py [--paths 30]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import robots
from planners.constraints import build_path_constraints
from planners.errors import InfeasiblePath, TimingFailed
from planners.grid import path_grid
from planners.paths import SplinePath
from planners.timing import PhasePlaneMethod, ToppraMethod

LADDER = (25, 50, 75, 100, 150, 200, 300, 450, 600, 900, 1200, 1800, 2400, 3600, 5000)
KINDS = ("velocity", "acceleration", "torque")
ACCURACY = 1e-3


def _random_path(robot, rng):
    lower = np.maximum(robot.limits.position_lower, -3.0)
    upper = np.minimum(robot.limits.position_upper, 3.0)
    margin = 0.15 * (upper - lower)
    while True:
        path = SplinePath(rng.uniform(lower + margin, upper - margin, (int(rng.integers(2, 6)), robot.dof)))
        q = path(np.linspace(0, 1, 500))
        if np.all(q >= lower) and np.all(q <= upper):
            return path


def _best_of(method, constraints, repeats=3):
    best, result = np.inf, None
    for _ in range(repeats):
        started = time.perf_counter()
        result = method.solve(constraints)
        best = min(best, time.perf_counter() - started)
    return best, result


def _equal_accuracy(method, path, robot, reference):
    """(grid, solve seconds, build seconds, duration) at the smallest ladder grid within ACCURACY."""
    for n in LADDER:
        started = time.perf_counter()
        constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, n))
        build = time.perf_counter() - started
        seconds, result = _best_of(method, constraints)
        if abs(result.duration / reference - 1) <= ACCURACY:
            return n, seconds, build, result.duration
    return None


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paths", type=int, default=30, help="paths per robot")
    args = parser.parse_args()
    toppra, phase_plane = ToppraMethod(), PhasePlaneMethod()
    warm = robots.load("ur5")
    warm_path = _random_path(warm, np.random.default_rng(0))
    phase_plane.solve(build_path_constraints(warm_path, warm, warm.limits, KINDS, path_grid(warm_path, 50)))
    toppra.solve(build_path_constraints(warm_path, warm, warm.limits, KINDS, path_grid(warm_path, 50)))
    ratios, totals, slower = [], [], []
    print(f"{'robot':6s} {'path':>4s} {'T ref s':>9s} | {'toppra N':>8s} {'ms':>7s} | {'pp N':>6s} {'ms':>7s} | {'ratio':>6s} {'ratio incl. build':>17s}")
    for name in ("ur5", "panda"):
        robot = robots.load(name)
        rng = np.random.default_rng(99 if name == "ur5" else 98)
        done = 0
        while done < args.paths:
            path = _random_path(robot, rng)
            try:
                reference = toppra.solve(build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, 10_000))).duration
            except (InfeasiblePath, TimingFailed):
                continue
            theirs = _equal_accuracy(toppra, path, robot, reference)
            ours = _equal_accuracy(phase_plane, path, robot, reference)
            if theirs is None or ours is None:
                print(f"{name:6s} {done:4d}: a method missed 0.1 % on every grid of the ladder: toppra {theirs}, phase_plane {ours}")
                done += 1
                continue
            ratio = theirs[1] / ours[1]
            total = (theirs[1] + theirs[2]) / (ours[1] + ours[2])
            ratios.append(ratio)
            totals.append(total)
            if ratio < 1:
                slower.append((name, done, theirs, ours))
            print(
                f"{name:6s} {done:4d} {reference:9.4f} | {theirs[0]:8d} {1e3 * theirs[1]:7.2f} | "
                f"{ours[0]:6d} {1e3 * ours[1]:7.2f} | {ratio:6.2f} {total:17.2f}"
            )
            done += 1
    ratios, totals = np.array(ratios), np.array(totals)
    print()
    print(f"paths compared: {len(ratios)}")
    print(f"solve-time ratio toppra / phase_plane: median {np.median(ratios):.2f}, p95 {np.percentile(ratios, 95):.2f}, "
          f"p5 {np.percentile(ratios, 5):.2f}, min {ratios.min():.2f}")
    print(f"including the constraint build:        median {np.median(totals):.2f}, p95 {np.percentile(totals, 95):.2f}, "
          f"p5 {np.percentile(totals, 5):.2f}, min {totals.min():.2f}")
    for name, index, theirs, ours in slower:
        print(f"slower: {name} path {index}: toppra N={theirs[0]} {1e3 * theirs[1]:.2f} ms, phase_plane N={ours[0]} {1e3 * ours[1]:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
