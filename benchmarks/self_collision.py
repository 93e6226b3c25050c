"""The self-collision check of a given path against one bare toppra solve of the same path,
measured in the same run: the typical request's ur5 path (``end_to_end.WAYPOINTS``) with
``path.self_collision`` asked, and a path folding the arm onto itself (refused).

    python benchmarks/self_collision.py [--rounds 5]

Each round times one check between two bare toppra solves (``anchors.bare_toppra``); printed
per path: the median check time, its ratio to the median solve, and how many configurations
the check took (the first pass and its refinement near contact).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT.parent))
sys.path.insert(0, str(ROOT))

from anchors import bare_toppra  # noqa: E402
from end_to_end import WAYPOINTS  # noqa: E402

from toptraj import robots  # noqa: E402
from toptraj.planners.collision.self_collision import SelfCollision, check_self_collision  # noqa: E402
from toptraj.planners.paths import SplinePath  # noqa: E402

UPRIGHT = [0.0, -1.57, 0.0, -1.57, 0.0, 0.0]
FOLDED = [0.0, -1.57, 2.9, -1.57, 0.0, 0.0]


def _check(robot, path) -> str:
    try:
        found = check_self_collision(path, robot)
    except SelfCollision as error:
        return f"refused at s = {error.s:.4g} ({error.link_a}, {error.link_b})"
    return f"passes, {found.checked} configurations, closest {found.distance:.4g} m"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    robot = robots.load("ur5")
    cases = {
        "typical request's path": np.array(WAYPOINTS),
        "folding onto itself": np.array([UPRIGHT, np.add(UPRIGHT, FOLDED) / 2.0, FOLDED]),
    }
    for name, waypoints in cases.items():
        path = SplinePath(waypoints)
        outcome = _check(robot, path)  # warm: the pairs and the SRDF are read once per robot
        checks, solves = [], []
        for _ in range(args.rounds):
            began = time.perf_counter()
            bare_toppra(robot, waypoints)
            solves.append(time.perf_counter() - began)
            began = time.perf_counter()
            _check(robot, path)
            checks.append(time.perf_counter() - began)
            began = time.perf_counter()
            bare_toppra(robot, waypoints)
            solves.append(time.perf_counter() - began)
        check, solve = statistics.median(checks), statistics.median(solves)
        print(f"{name}: check {check * 1e3:.1f} ms = {check / solve:.2f}x one bare toppra solve ({solve * 1e3:.1f} ms); {outcome}")


if __name__ == "__main__":
    main()
