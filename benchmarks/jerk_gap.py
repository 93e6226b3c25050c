"""``jerk_limited``'s stated gap (``optimality_gap``) against its distance from a converged
reference, on seeded random spline paths.

For each of ``--paths`` seeded spline paths (ur5 and panda alternately, 4 waypoints within 30 %
of the joint ranges around their middle, torque limits scaled until holding the arm still takes
1 / 1.3 of them somewhere), the method times the path on its default grid (with its refinement)
and states its gap; the reference is the same method's grid solution on a grid ``--factor``
times finer than the answer's, extrapolated to zero interval with the observed first-order
convergence (T* = 2 T_fine - T_coarse, the coarse being the answer's grid doubled once). Prints,
per path: the answer's duration, its stated gap, its distance from the reference, and whether
the statement holds (stated >= actual); then the counts.

    python benchmarks/jerk_gap.py [--paths 6] [--factor 4]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from toptraj import robots
from toptraj.planners import WaypointPath
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.timing.base import AT_REST
from toptraj.planners.timing.jerk.accuracy import refined
from toptraj.planners.timing.jerk.method import JerkLimitedMethod

KINDS = ("velocity", "acceleration", "torque", "jerk")


def _case(name: str, seed: int):
    arm = robots.load(name)
    rng = np.random.default_rng(seed)
    lower, upper = arm.limits.position_lower, arm.limits.position_upper
    middle, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
    path = make_path(arm, WaypointPath(rng.uniform(middle - 0.3 * half, middle + 0.3 * half, size=(4, arm.dof))))
    q = path(np.linspace(0.0, 1.0, 400))
    gravity = np.abs(arm.inverse_dynamics(q, np.zeros_like(q), np.zeros_like(q))) / arm.limits.torque
    limits = arm.limits.with_request(scales={"torque": min(1.0, 1.3 * float(gravity.max()))})
    return arm, path, limits


def _refined(constraints, times: int):
    """Every interval halved ``times`` times, but the two at rest (``refined``)."""
    for _ in range(times):
        constraints = refined(constraints, AT_REST)
    return constraints


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paths", type=int, default=6)
    parser.add_argument("--factor", type=int, default=4, help="reference grid / answer grid (a power of 2)")
    args = parser.parse_args()
    doublings = int(round(np.log2(args.factor)))
    held = 0
    for index in range(args.paths):
        name = ("ur5", "panda")[index % 2]
        arm, path, limits = _case(name, 200 + index)
        constraints = build_path_constraints(path, arm, limits, KINDS, path_grid(path))
        method = JerkLimitedMethod(polish=False)
        started = time.perf_counter()
        answer = method.solve(constraints)
        elapsed = time.perf_counter() - started
        # The answer's own grid (its s), refined; the reference extrapolated from the two finest.
        base = constraints.with_points(np.setdiff1d(answer.s, constraints.s))
        finer = _refined(base, doublings - 1)
        finest = _refined(finer, 1)
        coarse = method._grid_solution(finer, AT_REST, NO_DEADLINE, start=answer)
        fine = method._grid_solution(finest, AT_REST, NO_DEADLINE, start=coarse)
        reference = 2.0 * fine.duration - coarse.duration
        actual = (answer.duration - reference) / reference
        stated = answer.optimality_gap
        ok = stated is not None and stated >= actual
        held += ok
        print(
            f"{name} seed {200 + index}: T = {answer.duration:.6f} s on {len(answer.s) - 1} intervals ({elapsed:.1f} s), "
            f"stated gap {100 * (stated or np.nan):.3f} %, actual {100 * actual:.3f} % "
            f"(reference {reference:.6f} s from {len(finest.s) - 1} intervals): {'holds' if ok else 'DOES NOT HOLD'}",
            flush=True,
        )
    print(f"stated gap >= actual on {held} of {args.paths} paths")


if __name__ == "__main__":
    main()
