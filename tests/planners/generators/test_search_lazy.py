"""The roadmap's spans are checked lazily (Lazy PRM): only the spans of the grid paths the search
times, the search run again without those found blocked. It finds the grid paths the search
that checks every span first finds, having checked a small part of the spans, and the spans of
its paths keep the clearance by the full check."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners.collision import BoxObstacle
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.generators.search import method
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.generators.search.outcome import NoGridPath, SearchStatistics
from toptraj.planners.generators.search.problem import build_problem, with_spans_checked

UR5_START = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
UR5_GOAL = np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
PANDA_START = np.array([-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8])
PANDA_GOAL = np.array([0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8])
KINDS = ("velocity", "acceleration", "torque")


def _halfway_box(robot, start, goal, size: float) -> BoxObstacle:
    """A box of edge ``size`` (m) where the tool is halfway along the straight joint line."""
    pin.framesForwardKinematics(robot.model, robot.data, robot.configuration(((start + goal) / 2.0)[None])[0])
    return BoxObstacle(np.array(robot.data.oMf[robot.frame_id(robot.end_effector)].translation), np.full(3, size))


CASES = {
    # (robot, start, goal, box edge (m), clearance (m), roadmap points)
    "ur5": ("ur5", UR5_START, UR5_GOAL, 0.1, 0.01, 100),
    "panda": ("panda", PANDA_START, PANDA_GOAL, 0.1, 0.01, 100),
    "ur5, wide box": ("ur5", UR5_START, UR5_GOAL, 0.3, 0.02, 60),
}


def _searches(name: str, tubes: int = 3):
    robot_name, start, goal, size, clearance, points = CASES[name]
    robot = robots.load(robot_name)
    box = _halfway_box(robot, start, goal, size)
    found = {
        lazy: global_search(robot, robot.limits, KINDS, start, goal, SearchOptions(roadmap_points=points, tubes=tubes, lazy=lazy),
                            True, (box,), clearance)
        for lazy in (False, True)
    }
    return robot, box, clearance, points, found


@pytest.mark.parametrize("name", list(CASES))
def test_the_lazy_search_finds_the_grid_paths_of_the_full_check(name):
    """The same best grid path (points and time) and the same tubes, with a tenth of the spans
    checked or fewer; the eager search checks every span."""
    robot, box, clearance, points, found = _searches(name)
    eager, lazy = found[False].result, found[True].result
    assert [tube.time for tube in lazy.tubes] == pytest.approx([tube.time for tube in eager.tubes], rel=1e-12)
    for mine, theirs in zip(lazy.tubes, eager.tubes):
        assert np.array_equal(mine.points, theirs.points)
    spans = eager.statistics.spans_checked
    problem = build_problem(robot, robot.limits, KINDS, CASES[name][1], CASES[name][2], SearchOptions(roadmap_points=points, lazy=False), True, (box,), clearance)
    assert spans == len(problem.pieces) and eager.statistics.searches == 1
    assert lazy.statistics.spans_checked <= spans / 10


def test_a_box_on_the_straight_line_makes_the_lazy_search_start_again():
    """ur5's straight joint line meets the box: the first search's best path is the direct
    span, found blocked when checked, so a second search runs without it and ends on a clear
    path. A lazy problem starts with no span checked; checking them all gives the eager
    problem's usable spans, removed count and costs to go."""
    robot, box, clearance, points, found = _searches("ur5")
    lazy = found[True].result
    assert lazy.statistics.searches >= 2 and lazy.statistics.removed_by_obstacles >= 1
    eager_problem = build_problem(robot, robot.limits, KINDS, UR5_START, UR5_GOAL, SearchOptions(roadmap_points=points), True, (box,), clearance)
    lazy_problem = build_problem(robot, robot.limits, KINDS, UR5_START, UR5_GOAL, SearchOptions(roadmap_points=points, lazy=True), True, (box,), clearance)
    assert eager_problem.checked.all() and not lazy_problem.checked.any()
    assert lazy_problem.usable.sum() > eager_problem.usable.sum()
    checked, blocked = with_spans_checked(lazy_problem, np.arange(len(lazy_problem.pieces))[::-1])
    assert blocked == eager_problem.removed > 0 and checked.removed == eager_problem.removed
    assert np.array_equal(checked.usable, eager_problem.usable) and np.array_equal(checked.h2, eager_problem.h2)


def test_after_its_attempts_the_lazy_search_checks_every_span(monkeypatch):
    """With no search left before the full check (``LAZY_ATTEMPTS`` 0 and 1), the search checks
    every span and answers as the eager search does."""
    robot, box, clearance, points, found = _searches("ur5", tubes=1)
    eager = found[False].result
    for attempts in (0, 1):
        monkeypatch.setattr(method, "LAZY_ATTEMPTS", attempts)
        forced = global_search(robot, robot.limits, KINDS, UR5_START, UR5_GOAL, SearchOptions(roadmap_points=points, tubes=1), True, (box,), clearance).result
        assert forced.statistics.searches == attempts + 1
        assert forced.statistics.spans_checked == eager.statistics.spans_checked
        assert forced.statistics.removed_by_obstacles == eager.statistics.removed_by_obstacles
        assert forced.tubes[0].time == pytest.approx(eager.tubes[0].time, rel=1e-12)
        assert np.array_equal(forced.tubes[0].points, eager.tubes[0].points)


def test_the_lazy_searches_share_one_quarter_of_the_time_left(monkeypatch):
    """However many searches the lazy loop runs, their branch and bounds take together
    ``SEARCH_SHARE`` of the time left when the first began, not that share each: here every
    search spends its whole allowance and times a span found blocked, until the last."""
    robot, box, clearance, points, _ = _searches("ur5", tubes=1)
    spent: list[float] = []

    def stubborn(problem, options, deadline, cap, allowance_s):
        began = time.monotonic()
        time.sleep(allowance_s)
        spent.append(time.monotonic() - began)
        unchecked = np.flatnonzero(~problem.checked & problem.usable)
        raise NoGridPath("no grid path within the allowance", SearchStatistics("roadmap", 0, 0, [], 0, 0, 0, 1.0), unchecked[:1])

    def all_blocked(problem, spans, deadline=None, states=True):
        spans = np.unique(np.asarray(spans, dtype=int))
        spans = spans[~problem.checked[spans]]
        checked, usable = problem.checked.copy(), problem.usable.copy()
        checked[spans], usable[spans] = True, False
        return dataclasses.replace(problem, checked=checked, usable=usable), len(spans)

    monkeypatch.setattr(method, "branch_and_bound", stubborn)
    monkeypatch.setattr(method, "with_spans_checked", all_blocked)
    budget = Deadline(4.0)
    with pytest.raises(NoGridPath):
        global_search(robot, robot.limits, KINDS, UR5_START, UR5_GOAL, SearchOptions(roadmap_points=points, tubes=1), True, (box,), clearance, budget)
    assert len(spent) == method.LAZY_ATTEMPTS + 1
    assert sum(spent) <= method.SEARCH_SHARE * 4.0 + 0.1
