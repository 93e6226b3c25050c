"""What a payload and a mounting cost a request: building the equipped robot (a copy of the model
with the payload's inertia added and the base pose applied, ``toptraj.robots.equipment``), and
finding it in the cache, against one library planning of the typical request (ur5, 4 spline
waypoints, velocity + acceleration + torque, ``phase_plane``), timed interleaved in one run.

    python benchmarks/equipment.py --rounds 200

Prints the medians and their ratios to the planning of the bare arm: a moved arm's planning
(the same dynamics: the equipped robot's overhead alone), and a newly moved arm's (built, then
planned with its first computation of the kinematic tables). A cache miss happens once per distinct payload and mounting (32 kept per process).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.robots import equipment


def _ms(call) -> float:
    start = time.perf_counter()
    call()
    return (time.perf_counter() - start) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=200)
    rounds = parser.parse_args().rounds
    ur5 = robots.load("ur5")
    base = equipment.mounting(position=(0.0, 0.0, 2.2), orientation=(1.0, 0.0, 0.0, 0.0))
    path = WaypointPath(np.array(UR5_WAYPOINTS), "spline")
    timing = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration", "torque")))
    cached = equipment.equip(ur5, mounting=equipment.mounting(position=(1.0, 0.0, 0.0)))  # the same dynamics
    plan(build_problem(cached, path, **timing, sampling=Sampling(dt=0.01)))  # compile and warm
    built, found, planned, planned_equipped, planned_fresh = [], [], [], [], []
    for k in range(rounds):
        load = equipment.payload(1.0 + k * 1e-3, (0.0, 0.0, 0.1))  # a new payload each round: a cache miss
        built.append(_ms(lambda load=load: equipment.equip(ur5, load, base)))
        found.append(_ms(lambda: equipment.equip(ur5, equipment.payload(2.0, (0.0, 0.0, 0.1)), base)))
        planned.append(_ms(lambda: plan(build_problem(ur5, path, **timing, sampling=Sampling(dt=0.01)))))
        planned_equipped.append(_ms(lambda: plan(build_problem(cached, path, **timing, sampling=Sampling(dt=0.01)))))
        moved = equipment.mounting(position=(2.0 + k * 1e-3, 0.0, 0.0))  # a new robot, the same dynamics
        planned_fresh.append(_ms(lambda moved=moved: plan(build_problem(equipment.equip(ur5, mounting=moved), path, **timing, sampling=Sampling(dt=0.01)))))
    anchor = statistics.median(planned)
    for name, times in (("equip, cache miss", built), ("equip, cache hit", found), ("plan, bare ur5", planned),
                        ("plan, moved ur5", planned_equipped), ("move anew and plan", planned_fresh)):
        median = statistics.median(times)
        print(f"{name:20s} median {median:8.3f} ms = {median / anchor:6.3f}x one planning")


if __name__ == "__main__":
    main()
