"""The free-path collocation's NLP solved by the dense SQP (SLSQP) and by IPOPT on its sparse
KKT system, on the same problems from the same start, interleaved.

    python benchmarks/free_path.py [--intervals 12,30,100] [--robots yamamoto_2r,ur5] [--slsqp-max 30]

Each problem starts from the straight line timed time-optimally along itself (the collocation's
first guess). Prints, per robot and number of intervals, the minimum time each solver reaches,
its iterations and its wall time (IPOPT's includes building the CasADi expressions). SLSQP is
run only up to ``--slsqp-max`` intervals: beyond, its dense QP takes minutes.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from toptraj import robots  # noqa: E402
from toptraj.planners.generators.collocation import collocation  # noqa: E402
from toptraj.planners.generators.collocation.sparse import solve_sparse  # noqa: E402

MOTIONS = {
    "yamamoto_2r": (np.radians([45.0, -90.0]), np.radians([-90.0, 0.0])),
    "geering_2r": (np.zeros(2), np.array([0.76, -2 * np.pi])),
    "ur5": (np.array([0.0, -1.2, 1.0, 0.0, 0.0, 0.0]), np.array([0.8, -1.0, 1.4, -0.5, 0.6, 0.3])),
    "panda": (np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8]), np.array([0.8, 0.2, 0.3, -1.2, 0.4, 2.2, 0.2])),
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--intervals", default="12,30,100")
    parser.add_argument("--robots", default="yamamoto_2r,geering_2r,ur5,panda")
    parser.add_argument("--slsqp-max", type=int, default=30)
    args = parser.parse_args()
    print(f"{'robot':12s} {'K':>5s}  {'solver':6s} {'T (s)':>10s} {'iter':>5s} {'wall (s)':>9s}")
    for name in args.robots.split(","):
        robot = robots.load(name)
        start, goal = MOTIONS[name]
        for K in (int(k) for k in args.intervals.split(",")):
            motion = collocation.FreeMotion(start, goal, intervals=K, revolutions=False)
            problem = collocation._Problem(robot, robot.limits, motion, goal, 0.0)
            z0 = collocation._timed_guess(problem, np.zeros(robot.dof))
            started = time.perf_counter()
            sparse = solve_sparse(problem, z0, 3000)
            wall = time.perf_counter() - started
            print(f"{name:12s} {K:5d}  {'ipopt':6s} {sparse.fun:10.6f} {sparse.nit:5d} {wall:9.2f}", flush=True)
            if K <= args.slsqp_max:
                started = time.perf_counter()
                dense, feasible = collocation._solve(problem, z0, 1000)
                wall = time.perf_counter() - started
                mark = "" if feasible else "  (infeasible)"
                print(f"{name:12s} {K:5d}  {'slsqp':6s} {dense.fun:10.6f} {dense.nit:5d} {wall:9.2f}{mark}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
