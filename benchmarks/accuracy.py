"""Accuracy study: each method's default answer and its stated accuracy against a converged
reference, on seeded paths of several kinds.

* ``spline``: seeded random spline paths (``benchmarks/converged.py``) of ur5, panda and the
  two-link paper arms; reference: the Richardson-converged phase-plane duration there
  (10,000 and 20,000 intervals, checked against the midpoint discretization).
* ``recorded``: recorded paths of ur5 and panda, whose first two steps are tiny next to the
  rest (as in the data shipped with toppra's tests); the same reference.
* ``weld``: straight lines of ur5's tool at 5 to 50 cm/s (``timing.limits.tool_speed``);
  reference: TOPP-RA through toptraj's adapter on 20,000 intervals (its own error there is
  about 1e-5).

For every answer: the true gap (duration / reference - 1), the stated one
(``accuracy.relative_gap``) and whether a warning gives the figure. Prints one line per family
and method: answers, the largest true and stated gaps, the largest understatement (true gap
minus stated, when positive), the answers more than 0.1 % above the reference, and how many of
those carry no warning (the policy's promise: none).

    python benchmarks/accuracy.py --paths 5
    python benchmarks/accuracy.py --families spline --robots ur5,geering_2r --methods toppra --paths 15
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from benchmarks.converged import converged_duration as converged_spline
from benchmarks.converged import random_path
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.kinematics.ik import frame_pose
from toptraj.planners.paths import SplinePath
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.paths.grid import MAX_POINTS, path_grid
from toptraj.planners.runner.accuracy import GAP_TARGET
from toptraj.planners.timing.toppra_method import ToppraMethod

KINDS = ("velocity", "acceleration", "torque")
UR5_START = np.array([0.3, -1.6, 1.7, -1.6, -1.57, 0.2])


def random_waypoints(robot, rng) -> np.ndarray:
    """2 to 5 waypoints within the middle 70 % of each joint's range (+-pi for continuous ones)."""
    lower = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.35 * (upper - lower)
    return middle + rng.uniform(-1, 1, (int(rng.integers(2, 6)), robot.dof)) * half


def converged_duration(robot, waypoints) -> float:
    """TOPP-RA through the adapter on 20,000 intervals of the spline through ``waypoints``."""
    path = SplinePath(waypoints)
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, MAX_POINTS))
    return ToppraMethod().solve(constraints).duration


def recorded_waypoints(robot, rng, count: int = 5) -> np.ndarray:
    """A recorded path: two tiny first steps (2e-4 and 1.6e-4 of a 3 rad path), then random
    steps within the middle 60 % of each joint's range."""
    lower = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.3 * (upper - lower)
    points = [middle + rng.uniform(-1, 1, robot.dof) * half]
    for fraction in (2e-4, 1.6e-4):
        step = rng.normal(size=robot.dof)
        points.append(points[-1] + 3.0 * fraction * step / np.linalg.norm(step))
    while len(points) < count:
        points.append(np.clip(points[-1] + rng.uniform(-1, 1, robot.dof) * half, middle - half, middle + half))
    return np.array(points)


def _cases(family: str, robot_names: list[str], paths: int, seed: int):
    """(label, robot, path spec, tool speed (m/s, or None), reference duration) for one family."""
    if family == "weld":
        arm = robots.load("ur5")
        rng = np.random.default_rng(seed)
        p0 = frame_pose(arm, UR5_START, arm.frame_id("tool0")).translation
        for k in range(paths):
            offset = rng.uniform(-1, 1, 3) * np.array([0.15, 0.3, 0.15])
            speed = float(rng.choice([0.05, 0.1, 0.25, 0.5]))
            line = CartesianLine(start=UR5_START, positions=np.array([p0 + offset]))
            try:
                asked = LimitRequest(kinds=KINDS, tool_speed=speed)
                problem = build_problem(arm, line, METHODS["toppra"], limits=asked, grid=MAX_POINTS, sampling=Sampling(1.0))
                reference = plan(problem).duration
            except (InfeasiblePath, TimingFailed):
                continue
            yield f"weld {k} at {speed:g} m/s", arm, line, speed, reference
        return
    for name in robot_names:
        robot = robots.load(name)
        rng = np.random.default_rng(seed)
        for k in range(paths):
            if family == "spline":
                waypoints, path = random_path(robot, rng)
            else:
                waypoints = recorded_waypoints(robot, rng)
                path = SplinePath(waypoints)
            try:
                reference, _ = converged_spline(path, robot)
            except (InfeasiblePath, TimingFailed):
                continue
            # Every waypoint kept: the reference is the spline through all of them.
            yield f"{name} {family} {k}", robot, WaypointPath(waypoints, min_spacing=0.0), None, reference


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", default="spline,recorded,weld")
    parser.add_argument("--robots", default="ur5,panda,geering_2r,yamamoto_2r")
    parser.add_argument("--methods", default="phase_plane,toppra,min_cost")
    parser.add_argument("--paths", type=int, default=5)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--verbose", action="store_true", help="one line per answer")
    args = parser.parse_args()
    methods = args.methods.split(",")
    print(f"{'family':10s} {'method':12s} {'n':>3s} {'max true':>10s} {'max stated':>10s} "
          f"{'understated':>11s} {'>0.1%':>5s} {'unwarned':>8s} {'failed':>6s} {'median s':>8s}")
    for family in args.families.split(","):
        names = args.robots.split(",") if family == "spline" else [n for n in args.robots.split(",") if n in ("ur5", "panda")]
        rows: dict[str, list] = {method: [] for method in methods}
        failed = dict.fromkeys(methods, 0)
        for label, robot, spec, tool_speed, reference in _cases(family, names, args.paths, args.seed):
            for method in methods:
                started = time.perf_counter()
                try:
                    asked = LimitRequest(kinds=KINDS, tool_speed=tool_speed)
                    result = plan(build_problem(robot, spec, METHODS[method], limits=asked, sampling=Sampling(0.05)))
                except (InfeasiblePath, TimingFailed) as error:
                    failed[method] += 1
                    if args.verbose:
                        print(f"  {label:28s} {method:12s} {type(error).__name__}: {str(error)[:80]}")
                    continue
                seconds = time.perf_counter() - started
                true_gap = result.duration / reference - 1.0
                stated = None if result.accuracy is None else result.accuracy.relative_gap
                warned = any("of the time-optimal one" in text for text in result.warnings)
                rows[method].append((true_gap, stated, warned, seconds))
                if args.verbose:
                    print(f"  {label:28s} {method:12s} true {true_gap:+.2e} stated {stated if stated is None else f'{stated:.2e}'} "
                          f"warned {warned} {seconds:.2f} s")
        for method, values in rows.items():
            if not values:
                print(f"{family:10s} {method:12s} {0:3d} (no answers; failed {failed[method]})")
                continue
            true_gaps = np.array([v[0] for v in values])
            stated = np.array([np.nan if v[1] is None else v[1] for v in values])
            over = true_gaps > GAP_TARGET
            unwarned = int(np.sum(over & ~np.array([v[2] for v in values])))
            understated = np.nanmax(np.maximum(true_gaps - stated, 0.0))
            print(
                f"{family:10s} {method:12s} {len(values):3d} {true_gaps.max():10.2e} {np.nanmax(stated):10.2e} "
                f"{understated:11.2e} {int(over.sum()):5d} {unwarned:8d} {failed[method]:6d} {np.median([v[3] for v in values]):8.2f}"
            )


if __name__ == "__main__":
    main()
