"""The limit promise on many seeded random requests: robots of 1 to 7 joints (two uploaded test
arms from tests/data and catalog arms), every path-timing method, spline and stop-and-go paths,
half of them starting with two tiny segments (a recorded path), with and without a margin.

    python benchmarks/limits_study.py --cases 40 [--methods phase_plane,toppra] [--grid-points 30]

Each answer is checked on its own samples at dt = 1 ms (joint velocity, acceleration, torque,
and accelerations as finite differences of the returned velocities). Prints, per method, the
number of answers, of 422s, the largest |value| / limit without a margin, and with a margin of
0.2 % (where it must stay at or below 1).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pinocchio as pin

from toptraj import robots
from toptraj.planners import METHODS as TIMING_METHODS
from toptraj.planners import LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.robots.catalog import robot_from_model

DATA = Path(__file__).parent.parent / "tests" / "data"
KINDS = ("velocity", "acceleration", "torque")
METHODS = ("phase_plane", "toppra", "min_cost", "cubic", "quintic", "trapezoidal", "cycloidal")


def test_arms():
    arms = []
    for stem, tip in (("pendulum_1r", "tip"), ("lift_rp", "hand")):
        model = pin.buildModelFromXML((DATA / f"{stem}.urdf").read_text())
        arms.append(robot_from_model(stem, model, "upload", tip))
    return arms + [robots.load(name) for name in ("yamamoto_2r", "lecture_3r", "ur5", "panda")]


def waypoints(robot, rng, tiny: bool) -> np.ndarray:
    lower = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.3 * (upper - lower)
    points = [middle + rng.uniform(-1, 1, robot.dof) * half]
    if tiny:
        for fraction in (2e-4, 1.6e-4):
            step = rng.normal(size=robot.dof)
            points.append(points[-1] + 3.0 * fraction * step / np.linalg.norm(step))
    while len(points) < int(rng.integers(3, 7)):
        points.append(np.clip(points[-1] + rng.uniform(-1, 1, robot.dof) * half, middle - half, middle + half))
    return np.array(points)


def worst(result, limits) -> float:
    samples = result.samples
    ratios = [np.max(np.abs(samples.qd) / limits.velocity), np.max(np.abs(samples.qdd) / limits.acceleration),
              np.max(np.abs(samples.tau) / limits.torque)]
    steps = np.diff(samples.t)
    even = steps > 0.5 * np.median(steps)
    ratios.append(np.max(np.abs(np.diff(samples.qd, axis=0)[even] / steps[even][:, None]) / limits.acceleration))
    return float(max(ratios))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=40, help="requests per robot")
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--methods", default=",".join(METHODS), help="comma-separated; the cases cycle through them")
    parser.add_argument("--grid-points", type=int, default=None, help="timing.grid_points of every request (default: the service's)")
    args = parser.parse_args()
    methods = tuple(args.methods.split(","))
    rng = np.random.default_rng(args.seed)
    stats = {method: {"answers": 0, "refused": 0, "worst": 0.0, "worst_margin": 0.0} for method in methods}
    for robot in test_arms():
        for case in range(args.cases):
            method = methods[case % len(methods)]
            margin = 0.002 if case % 3 == 0 else 0.0
            spec = WaypointPath(waypoints(robot, rng, case % 2 == 0), "linear" if case % 5 == 0 else "spline")
            try:
                result = plan(build_problem(robot, spec, TIMING_METHODS[method], limits=LimitRequest(kinds=KINDS, margin=margin), grid=args.grid_points, sampling=Sampling(dt=1e-3)))
            except (InfeasiblePath, TimingFailed):
                stats[method]["refused"] += 1
                continue
            stats[method]["answers"] += 1
            key = "worst_margin" if margin else "worst"
            stats[method][key] = max(stats[method][key], worst(result, robot.limits))
    print(f"{'method':12s} {'answers':>8s} {'422':>5s} {'max ratio':>10s} {'max ratio, margin 0.2 %':>24s}")
    for method, row in stats.items():
        print(f"{method:12s} {row['answers']:8d} {row['refused']:5d} {row['worst']:10.5f} {row['worst_margin']:24.5f}")


if __name__ == "__main__":
    main()
