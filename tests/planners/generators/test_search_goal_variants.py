"""Each goal variant's cost to go (``toptraj.planners.generators.search.problem``, h2 of Jeong &
Lee eq. 2.7 over the graph) counts the grid paths into that variant's goal only: a state whose
move ends at another variant's goal leads nowhere (no move leaves a goal point), so its h2 is
infinite and the branch and bound discards it by t1 at once. On the Geering example the search
then ends every variant by its bounds: the same best grid path as before, with a ninth of the
subsets expanded."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners.collision import SphereObstacle
from toptraj.planners.generators.search import branch_and_bound, build_problem
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.generators.search.problem import toward_goal

#: examples/geering_search_obstacle.json's sphere.
SPHERE = SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05)


@pytest.fixture(scope="module")
def problem():
    robot = robots.load("geering_2r")
    return build_problem(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), SearchOptions(tubes=3), True, (SPHERE,), 0.01)


def test_a_state_at_another_variants_goal_has_no_cost_to_go(problem):
    goals = problem.graph.goals
    for index, goal in enumerate(goals):
        variant = toward_goal(problem, index)
        others = np.isin(variant.state_point, np.delete(goals, index))
        own = variant.state_point == goal
        assert others.any() and own.any()
        assert np.all(np.isinf(variant.h2[others]))
        assert np.all(np.isinf(variant.h1[others]))
        # where the last span into its own goal is usable, the cost to go is finite
        assert np.isfinite(variant.h2[own]).any()


def test_each_variants_cost_to_go_bounds_its_own_best_grid_path(problem):
    """From the start, h2 toward each variant lies below the t2 of that variant's best grid path
    (an admissible bound), and the three variants' bounds differ: each is its own goal's."""
    starts = []
    for index in range(len(problem.graph.goals)):
        variant = toward_goal(problem, index)
        first = min(variant.h2[state] for _, state, _ in variant.start_moves if state >= 0)
        best = branch_and_bound(variant, SearchOptions(tubes=1)).tubes[0]
        np.testing.assert_allclose(best.points[-1], problem.graph.points[problem.graph.goals[index]])
        assert first <= best.bounds[1] * (1 + 1e-9)
        starts.append(first)
    assert len(set(starts)) == 3


def test_the_geering_example_ends_every_variant_by_its_bounds():
    """The elbow's -2 pi turn at 1.5107 s as before (when the variant one revolution up ran to
    ``max_expansions``: 220,891 subsets expanded in all, incomplete); now every variant's search
    completes, the one up finding its grid path the long way round."""
    robot = robots.load("geering_2r")
    found = global_search(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), SearchOptions(tubes=3), True, (SPHERE,), 0.01)
    stats = found.result.statistics
    assert found.result.tubes[0].time == pytest.approx(1.5107493207030294, rel=1e-12)
    assert stats.complete and stats.goal_variants == 3
    assert stats.expanded < 30_000
    ends = sorted(float(tube.points[-1][1]) for tube in found.result.tubes)
    assert ends == pytest.approx([-2.0 * np.pi, 0.0, 2.0 * np.pi], abs=1e-12)
