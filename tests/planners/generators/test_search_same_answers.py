"""The compiled search answers what the search answered before it was compiled, on the cases of
``tests/planners/generators/test_search.py`` and ``benchmarks/search_growth.py``: the same best grid path time, the
same pieces removed by the obstacles and the same count of subsets expanded (figures recorded
from the pure-Python search on the same cases); and the local optimization with its compiled
objective takes the rounds it took with the reference objective (the same evaluations per
round, the same exact durations)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners.collision import BoxObstacle, SphereObstacle
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.local import optimize_locally
from toptraj.planners.generators.search.method import global_search

GEERING_SPHERE = SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05)
#: The local optimization of the Geering example's tube with the reference objective (commit
#: c5c2840): (control points, evaluations, exact duration in s) of each round; it converged after
#: 12,501 evaluations at 0.9827875487847286 s.
GEERING_ROUNDS = (
    (4, 294, 1.0663973470316912), (5, 356, 1.0662778273856113), (7, 851, 1.0124686855084841), (9, 1400, 0.9883770726636693),
    (11, 1800, 0.9876480133174816), (13, 2200, 0.9840082369849308), (15, 2600, 0.9834403698238328), (17, 3000, 0.9827875487847286),
)


@pytest.fixture(scope="module")
def geering():
    """The Geering example's search (examples/geering_search_obstacle.json)."""
    robot = robots.load("geering_2r")
    found = global_search(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), SearchOptions(tubes=1), True, (GEERING_SPHERE,), 0.01)
    return robot, found


def test_the_geering_example_finds_the_same_grid_path_after_the_same_expansions(geering):
    """examples/geering_search_obstacle.json's search: the elbow's -2 pi turn at 1.5107 s, after
    24,318 subsets expanded over the three goal variants (238, 3,708 and 20,372 by the variants in
    the order searched; the pure-Python search, ``tests.planners.generators.search_reference``,
    expands and prunes the same), every variant ended by its bounds. Before each variant's cost to
    go counted its own goal only, the variant one revolution up ran to ``max_expansions``:
    220,891 expanded in all."""
    _, found = geering
    stats = found.result.statistics
    assert found.result.tubes[0].time == pytest.approx(1.5107493207030294, rel=1e-12)
    assert stats.expanded == 24_318 and stats.generated == 67_147
    assert stats.pruned == {"t1": 6_619, "t2": 7_134, "t3": 29_071, "t4": 0, "t_u": 0}
    assert stats.complete


def test_ur5_around_a_box_finds_the_same_roadmap_path():
    """benchmarks/search_growth.py's ur5 at 100 roadmap points: a 10 cm box where the tool is
    halfway along the straight joint line; best grid path 1.5796 s, 8 subsets expanded (every
    span checked before the search, as the pure-Python search did)."""
    robot = robots.load("ur5")
    start, goal = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    pin.framesForwardKinematics(robot.model, robot.data, robot.configuration(((start + goal) / 2.0)[None])[0])
    tool = np.array(robot.data.oMf[robot.frame_id(robot.end_effector)].translation)
    box = BoxObstacle(tool, np.array([0.1, 0.1, 0.1]))
    found = global_search(
        robot, robot.limits, ("velocity", "acceleration", "torque"), start, goal, SearchOptions(roadmap_points=100, tubes=1, lazy=False), True, (box,), 0.01
    )
    stats = found.result.statistics
    assert stats.best_grid_time == pytest.approx(1.5796, abs=1e-4)
    assert stats.expanded == 8 and stats.removed_by_obstacles > 0


def test_the_geering_examples_local_optimization_takes_the_same_rounds(geering):
    """The compiled objective equals the reference one to rounding, so Nelder-Mead walks the
    same simplices: every round spends the same evaluations and ends on the same path."""
    robot, found = geering
    optimum = optimize_locally(robot, found.result.tubes[0].points, robot.limits, ("torque",), (GEERING_SPHERE,), 0.01)
    rounds = optimum.statistics.rounds
    assert [(r.control_points, r.evaluations) for r in rounds] == [(count, spent) for count, spent, _ in GEERING_ROUNDS]
    assert [r.duration for r in rounds] == pytest.approx([duration for _, _, duration in GEERING_ROUNDS], rel=1e-9)
    assert optimum.statistics.evaluations == 12_501 and optimum.statistics.stopped == "converged"
    assert optimum.duration == pytest.approx(0.9827875487847286, rel=1e-9)
