"""The global search's requests against one bare toppra solve of the typical request, measured
in the same run (issue 35's goals: the Geering example <= 200x, ur5 around a box <= 1,000x,
panda around a box <= 2,000x, durations no worse than before).

    python benchmarks/search_speed.py [--rounds 2] [--cases geering ur5 panda]

Each case is planned as the service plans it (``toptraj.service.planning.plan_request``, the search in
its isolated worker) under its budget; each round times the case between two sets of five bare
toppra solves (``anchors.bare_toppra`` on the typical request's path), and the ratio is the
case's wall time over the median of those solves. Printed per case: the median wall time, the
ratio, the median duration found (and each round's: under a budget, the local optimization
stops when its share is spent, so the duration depends on the machine's speed at the time) and
the last round's search figures (graph build, branch and bound, local
optimization's evaluations), beside the figures measured before the search was compiled
(``BEFORE``: same machine, same command, on the commit before).
"""

from __future__ import annotations

import argparse
import json
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
from toptraj.planners.errors import ToptrajError  # noqa: E402
from toptraj.planners.execution.deadline import Deadline  # noqa: E402
from toptraj.service.planning import plan_request  # noqa: E402
from toptraj.service.schemas.trajectories import TrajectoryRequest  # noqa: E402

UR5_START, UR5_GOAL = [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0], [1.0, -1.2, 1.5, -1.9, -1.57, 0.0]
PANDA_START, PANDA_GOAL = [-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8], [0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]


def _free(robot: str, start, goal, box: dict, clearance: float) -> dict:
    return {
        "robot": robot,
        "path": {"kind": "free", "start": start, "goal": goal, "obstacles": [box], "clearance": clearance},
        "timing": {"method": "search", "search": {"tubes": 1}},
        "output": {"dt": 0.01},
    }


#: name: (request, budget in s, the goal's ratio)
CASES = {
    "geering": (json.loads((ROOT.parent / "examples" / "geering_search_obstacle.json").read_text()), 20.0, 200),
    # the box of tests/planners/generators/test_search.py, where the tool is halfway along the straight joint line
    "ur5": (_free("ur5", UR5_START, UR5_GOAL, {"kind": "box", "center": [0.626, 0.109, 0.29], "size": [0.15, 0.15, 0.15]}, 0.02), 45.0, 1_000),
    # the box of benchmarks/search_growth.py, where the tool is halfway along the straight joint line
    "panda": (_free("panda", PANDA_START, PANDA_GOAL, {"kind": "box", "center": [0.4854, 0.0, 0.491], "size": [0.1, 0.1, 0.1]}, 0.01), 45.0, 2_000),
}
#: The figures before: (wall s, ratio, duration s), from this command on the commit before the
#: compiled search (8019bba), on the same 2-core machine shared with other work.
#: ``None``: no answer within the budget (504).
BEFORE: dict[str, tuple[float, float | None, float | None]] = {
    "geering": (16.999, 1241.0, 0.99067),
    "ur5": (40.200, 3215.0, 0.95028),
    "panda": (45.18, None, None),
}


def _anchor(robot, waypoints, count: int = 5) -> list[float]:
    out = []
    for _ in range(count):
        began = time.perf_counter()
        bare_toppra(robot, waypoints)
        out.append(time.perf_counter() - began)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    args = parser.parse_args()
    import toppra

    toppra.setup_logging("WARNING")
    ur5, waypoints = robots.load("ur5"), np.array(WAYPOINTS)
    _anchor(ur5, waypoints)  # warm-up
    for name in args.cases:
        body, budget, goal = CASES[name]
        request = TrajectoryRequest.model_validate(body)
        try:  # warm-up: kernels compiled or loaded, the worker started
            plan_request(request, Deadline(10.0 * budget))
        except ToptrajError as error:  # compiling may take the budget's share of the search
            print(f"{name:<8} warm-up: {type(error).__name__}", flush=True)
        walls, anchors, answer, durations = [], [], None, []
        for _ in range(args.rounds):
            anchors += _anchor(ur5, waypoints)
            began = time.perf_counter()
            try:
                answer = plan_request(request, Deadline(budget))
                durations.append(answer.duration)
            except ToptrajError as error:
                print(f"{name:<8} {type(error).__name__} after {time.perf_counter() - began:.2f} s: {error}", flush=True)
                continue
            finally:
                walls.append(time.perf_counter() - began)
            anchors += _anchor(ur5, waypoints)
        wall, anchor = statistics.median(walls), statistics.median(anchors)
        if answer is None:
            continue
        report = answer.search  # a SearchReport
        stats, local = report.statistics, report.local[0] if report.local else None
        local_text = "none" if local is None else f"{local.evaluations} ({local.stopped}, {local.wall_s:.2f} s)"
        print(
            f"{name:<8} wall {wall:7.3f} s  ratio {wall / anchor:7.0f}x (goal <= {goal}x; toppra {1e3 * anchor:.2f} ms)  "
            f"duration {statistics.median(durations):.5f} s (rounds {', '.join(f'{d:.5f}' for d in durations)})  build {stats.prepare_s:.3f} s  "
            f"B&B {stats.search_s:.3f} s  expanded {stats.expanded}  local evaluations {local_text}",
            flush=True,
        )
        if name in BEFORE:
            w, r, d = BEFORE[name]
            if r is None or d is None:
                print(f"{'':<8} before: no answer within the budget ({w:.2f} s)")
            else:
                print(f"{'':<8} before {w:7.3f} s  ratio {r:7.0f}x  duration {d:.5f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
