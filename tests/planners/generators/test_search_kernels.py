"""The compiled branch and bound (``toptraj.planners.generators.search.search_kernels``) against the
pure-Python loop it replaced (``tests.planners.generators.search_reference``): on the Geering arm's lattices, with
and without an obstacle, every revolution variant of the goal, an upper margin and a cap, the
same grid paths are found with the same times and bounds, after the same subsets were
generated, expanded and pruned by each test."""

from __future__ import annotations

import numpy as np
import pytest

from tests.planners.generators.search_reference import reference_search
from toptraj import robots
from toptraj.planners.collision import SphereObstacle
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.generators.search import build_problem
from toptraj.planners.generators.search.branch_and_bound import _Search
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.problem import toward_goal

SPHERE = SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05)


def _compiled(problem, options, cap=np.inf) -> _Search:
    search = _Search(problem, options, NO_DEADLINE, cap)
    search.run()
    return search


@pytest.mark.parametrize(
    ("cells", "obstacles", "revolutions", "upper_margin", "cap"),
    [
        (5, (), False, 0.02, np.inf),
        (8, (SPHERE,), True, 0.02, np.inf),
        (8, (SPHERE,), True, 0.2, np.inf),
        (10, (SPHERE,), True, 0.02, 2.0),
    ],
)
def test_the_compiled_search_expands_and_finds_what_the_python_loop_did(cells, obstacles, revolutions, upper_margin, cap):
    robot = robots.load("geering_2r")
    options = SearchOptions(cells=(cells,), upper_margin=upper_margin)
    problem = build_problem(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), options, revolutions, obstacles, 0.01)
    found_any = False
    for goal in range(len(problem.graph.goals)):
        variant = toward_goal(problem, goal)
        compiled, reference = _compiled(variant, options, cap), reference_search(variant, options, cap)
        for key in ("expanded", "generated", "pruned", "t4_evaluations", "complete"):
            assert getattr(compiled.stats, key) == getattr(reference.stats, key), key
        assert compiled.t_u == reference.t_u
        assert len(compiled.found) == len(reference.found)
        for ours, theirs in zip(compiled.found, reference.found):
            assert ours.time == theirs.time and ours.bounds == theirs.bounds
            np.testing.assert_array_equal(ours.points, theirs.points)
        found_any |= bool(compiled.found)
    assert found_any


def test_the_node_table_stops_growing_at_its_most_bytes(monkeypatch):
    """The variant one revolution up, reached only the long way round (some 21,000 subsets
    expanded), fills a node table of a mebibyte first: at ``MAX_NODE_BYTES`` the search stops,
    incomplete, before ``max_expansions``."""
    import toptraj.planners.generators.search.node_table as node_table

    monkeypatch.setattr(node_table, "MAX_NODE_BYTES", 2**20)
    robot = robots.load("geering_2r")
    options = SearchOptions(max_expansions=10**8)
    problem = build_problem(robot, robot.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), options, True, (SPHERE,), 0.01)
    search = _compiled(toward_goal(problem, 2), options)
    assert not search.stats.complete and not search.found
    assert 0 < search.stats.expanded < 2**20 // node_table.ROW_BYTES
