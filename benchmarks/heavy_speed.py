"""The heavy methods against one bare toppra solve of the typical request, interleaved in one run.

Probes, timed in a shuffled order each round (medians kept):

* **bare toppra**: the anchor, one solve of the typical request's path (ur5, 4 spline waypoints,
  velocity + acceleration + torque) through toppra's own public API (``anchors.bare_toppra``);
* **jerk_limited**: ``examples/ur5_jerk_limited.json`` through ``toptraj.service.planning.plan_request``
  (the library call the server makes, limit gate and sampling included), with a 20 s budget;
* **jerk_limited_2000**: the same request on ``timing.grid_points`` 2,000 (a fine grid such as
  a weld path asks for);
* **collocation**: the ur5 free motion of ``benchmarks/free_path.py`` (velocity + acceleration +
  torque, the default grid) with a 20 s budget, so that, as in the server, the optimization runs
  in a worker process forked for it (``toptraj.planners.execution.isolated``), at its lower CPU
  priority;
* **collocation_inline**: the same without a budget, in the calling thread (no worker).

Prints each probe's median wall time and its ratio to the anchor's beside the goal of issue 35
(jerk_limited <= 10x, collocation <= 200x), the same ratio by this process's CPU time (steadier on a
shared machine; not for a probe whose work runs in a worker process), and each answer's duration
and stated gap.

    python benchmarks/heavy_speed.py [--rounds 7] [--probes jerk_limited,collocation]
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

TYPICAL_WAYPOINTS = np.array([
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
])
JERK = json.loads((ROOT / "examples" / "ur5_jerk_limited.json").read_text())
JERK_FINE = {**JERK, "timing": {**JERK["timing"], "grid_points": 2000}}
COLLOCATION = {
    "robot": "ur5",
    "path": {"kind": "free", "start": [0.0, -1.2, 1.0, 0.0, 0.3, 0.0], "goal": [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]},
    "timing": {"method": "collocation", "constraints": ["velocity", "acceleration", "torque"]},
    "output": {"dt": 0.01},
}
#: Probe name: (request body, goal as a multiple of bare toppra or None, whether under a budget).
PROBES = {
    "jerk_limited": (JERK, 10.0, True),
    "jerk_limited_2000": (JERK_FINE, None, True),
    "collocation": (COLLOCATION, 200.0, True),
    "collocation_inline": (COLLOCATION, None, False),
}
BUDGET_S = 20.0


def _timed(function) -> tuple[float, float]:
    """Wall time and this process's CPU time of one call (s)."""
    started, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - started, time.process_time() - cpu


def _report(times, failed, answers, over, rounds: int) -> None:
    """Each probe's medians and ratios to the anchor's (module docstring)."""
    anchor, anchor_cpu = (float(value) for value in np.median(times["bare toppra"], axis=0))
    print(f"{rounds} interleaved rounds; bare toppra (typical request) p50 {1e3 * anchor:.2f} ms wall, "
          f"{1e3 * anchor_cpu:.2f} ms CPU")
    for name in over:
        print(f"  {name:20s} exceeded its budget of {BUDGET_S:g} s")
    for name in answers:
        if not times[name]:
            print(f"  {name:20s} exceeded its budget of {BUDGET_S:g} s in every round")
            continue
        median, median_cpu = (float(value) for value in np.median(times[name], axis=0))
        ratio = median / anchor
        goal = PROBES[name][1]
        verdict = "" if goal is None else f"   goal <= {goal:g}x   {'met' if ratio <= goal else 'MISSED'}"
        # A worker process's CPU time is not this process's: only the wall time compares.
        cpu = f"{median_cpu / anchor_cpu:7.1f}x by CPU time" if not PROBES[name][2] or name.startswith("jerk") else "  (CPU in a worker)"
        answer = answers[name]
        gap = answer.accuracy.relative_gap if answer.accuracy is not None else None
        print(
            f"  {name:20s} p50 {1e3 * median:9.1f} ms  {ratio:7.1f}x bare toppra{verdict}; {cpu}   "
            f"(duration {answer.duration:.6f} s, stated gap {gap if gap is None else f'{gap:.2e}'})"
            + (f"; exceeded its budget in {failed[name]} of {rounds} rounds" if failed[name] else "")
        )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--probes", default=",".join(PROBES), help="comma-separated, of: " + ", ".join(PROBES))
    args = parser.parse_args()
    # Imported here, not at the top: a worker process imports this script again (as its
    # ``__mp_main__``), as a server's workers import its entry point, which is light.
    import toppra
    from anchors import bare_toppra

    from toptraj import robots
    from toptraj.planners.errors import BudgetExceeded
    from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
    from toptraj.service.planning import plan_request
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    toppra.setup_logging("WARNING")
    ur5 = robots.load("ur5")
    chosen = [name for name in args.probes.split(",") if name]
    requests = {name: TrajectoryRequest.model_validate(PROBES[name][0]) for name in chosen}
    probes = {"bare toppra": lambda: bare_toppra(ur5, TYPICAL_WAYPOINTS)}
    answers, over = {}, []
    plan_request(TrajectoryRequest.model_validate(JERK))  # the first call compiles the kernels
    for name, request in requests.items():
        budgeted = PROBES[name][2]
        try:
            answers[name] = plan_request(request, Deadline(BUDGET_S) if budgeted else NO_DEADLINE)  # warm-up, and the answer
        except BudgetExceeded:
            over.append(name)
            continue
        probes[name] = lambda request=request, budgeted=budgeted: plan_request(request, Deadline(BUDGET_S) if budgeted else NO_DEADLINE)
    for _ in range(3):
        probes["bare toppra"]()
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in probes}
    order = list(probes)
    shuffle = random.Random(1)
    failed: dict[str, int] = {name: 0 for name in probes}
    for _ in range(args.rounds):
        shuffle.shuffle(order)
        for name in order:
            try:
                times[name].append(_timed(probes[name]))
            except BudgetExceeded:
                failed[name] += 1
    _report(times, failed, answers, over, args.rounds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
