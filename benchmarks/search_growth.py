"""How the global search's cost grows with the resolution and the number of joints (Jeong &
Lee section 2: a lattice of m points per joint has m^n points and 3^n - 1 moves from each;
arms with many joints search a roadmap instead).

    python benchmarks/search_growth.py [--quick] [--arms geering_2r lecture_3r ur5 panda]

For each arm and resolution: the graph's size (grid points, edges, turns of the direction-
augmented graph, pieces of curve bounded), the time to build the problem (pieces, their
configuration-space obstacle check and their bounds) and the branch and bound's time, nodes
expanded and pruning. Local optimization is not included (its cost is that of the timings
along the candidates, see the README). Lattices: geering_2r (2 joints) and lecture_3r (3);
roadmaps: ur5 (6) and panda (7), each with one box on the straight joint line, every span
checked before the branch and bound (``SearchOptions.lazy`` false; the search checks a
roadmap's spans lazily by default, see ``benchmarks/search_speed.py``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from toptraj import robots  # noqa: E402
from toptraj.planners.collision import BoxObstacle, SphereObstacle  # noqa: E402
from toptraj.planners.errors import InfeasiblePath  # noqa: E402
from toptraj.planners.generators.search.graph import SearchOptions  # noqa: E402
from toptraj.planners.generators.search.method import global_search  # noqa: E402
from toptraj.planners.generators.search.problem import build_problem  # noqa: E402

KINDS = {
    "geering_2r": ("torque",),
    "lecture_3r": ("velocity", "acceleration", "torque"),
    "ur5": ("velocity", "acceleration", "torque"),
    "panda": ("velocity", "acceleration", "torque"),
}


def _motion(name: str, robot):
    if name == "geering_2r":
        return np.zeros(2), np.array([0.76, 0.0]), [SphereObstacle(np.array([0.604, 0.241, 0.0]), 0.03)]
    if name == "lecture_3r":
        start, goal = np.array([0.0, 0.6, 0.6]), np.array([1.5, 0.6, 0.6])
    elif name == "ur5":
        start, goal = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    else:
        start, goal = np.array([-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]), np.array([0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8])
    # where the tool is halfway along the straight joint line: a box, or for the small lecture
    # arm a sphere of 3 cm
    import pinocchio as pin

    middle = robot.configuration(((start + goal) / 2.0)[None])[0]
    pin.framesForwardKinematics(robot.model, robot.data, middle)
    tool = np.array(robot.data.oMf[robot.frame_id(robot.end_effector)].translation)
    if name == "lecture_3r":
        return start, goal, [SphereObstacle(tool, 0.03)]
    return start, goal, [BoxObstacle(tool, np.array([0.1, 0.1, 0.1]))]


def run(name: str, options: SearchOptions) -> dict:
    robot = robots.load(name)
    start, goal, obstacles = _motion(name, robot)
    began = time.perf_counter()
    problem = build_problem(robot, robot.limits, KINDS[name], start, goal, options, True, obstacles, 0.01)
    prepared = time.perf_counter() - began
    began = time.perf_counter()
    found = global_search(robot, robot.limits, KINDS[name], start, goal, options, True, obstacles, 0.01)
    total = time.perf_counter() - began
    stats = found.result.statistics
    return {
        "arm": name,
        "n": robot.dof,
        "graph": stats.graph,
        "resolution": "x".join(map(str, stats.grid_shape)) if stats.grid_shape else f"{options.roadmap_points} points",
        "points": stats.grid_points,
        "edges": stats.grid_edges,
        "turns": stats.turns,
        "pieces": len(problem.pieces.kind),
        "build_s": prepared,
        "search_s": stats.search_s,
        "total_s": total,
        "expanded": stats.expanded,
        "pruned": stats.pruned,
        "best": stats.best_grid_time,
    }


#: Memory cap of the searches of this study, in bytes.
STUDY_MEMORY = 8 * 2**30


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the smaller resolutions only")
    parser.add_argument("--arms", nargs="+", default=list(KINDS), choices=list(KINDS), help="the arms to run")
    args = parser.parse_args()
    # a study of growth: the largest resolutions are beyond the service's memory cap (the
    # 3-joint lattice at 10 cells is estimated at 3 GiB), so the cap is raised here
    study = STUDY_MEMORY
    cases = [("geering_2r", SearchOptions(cells=(c,), memory_bytes=study)) for c in (8, 16, 24, 32)]
    cases += [("lecture_3r", SearchOptions(cells=(c,), memory_bytes=study)) for c in (6, 8, 10)]
    cases += [(arm, SearchOptions(roadmap_points=p, memory_bytes=study, lazy=False)) for arm in ("ur5", "panda") for p in (50, 100, 150)]
    cases = [case for case in cases if case[0] in args.arms]
    if args.quick:
        cases = [case for case in cases if (case[1].cells or (0,))[0] <= 16 and case[1].roadmap_points <= 100]
    header = f"{'arm':<11} {'n':>2} {'graph':<8} {'resolution':<11} {'points':>7} {'edges':>7} {'turns':>7} {'pieces':>7} {'build s':>8} {'ms/piece':>8} {'B&B s':>7} {'expanded':>8}  pruned t1/t2/t3/t4/t_u   best grid s"
    print(header)
    for name, options in cases:
        try:
            row = run(name, options)
        except InfeasiblePath as error:
            print(f"{name:<11} {options}: {error}", flush=True)
            continue
        pruned = "/".join(str(row["pruned"][k]) for k in ("t1", "t2", "t3", "t4", "t_u"))
        print(
            f"{row['arm']:<11} {row['n']:>2} {row['graph']:<8} {row['resolution']:<11} {row['points']:>7} {row['edges']:>7} "
            f"{row['turns']:>7} {row['pieces']:>7} {row['build_s']:>8.2f} {1e3 * row['build_s'] / max(row['pieces'], 1):>8.3f} {row['search_s']:>7.2f} {row['expanded']:>8}  "
            f"{pruned:<22} {row['best']:.4f}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
