"""The global search's typed report (``toptraj.planners.generators.search.report``) on the
Geering arm's free motion phi 0 -> 0.76 rad (Jeong & Lee section 2, Fig. 3: 0.9755 s)."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import LimitRequest, Sampling, build_problem, plan
from toptraj.planners.generators.search.generator import Search
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.report import SearchReport
from toptraj.planners.problem.free_motion import FreeMotion

GEERING_OPTIMUM = 0.9755


def test_the_search_reports_its_tubes_local_optimization_and_final_time():
    arm = robots.load("geering_2r")
    goal = np.array([0.76, 0.0])
    motion = FreeMotion(np.zeros(2), goal)
    result = plan(build_problem(arm, motion, Search(SearchOptions(tubes=1)), limits=LimitRequest(kinds=("torque",)), sampling=Sampling(dt=0.002)))
    report = result.search
    assert isinstance(report, SearchReport)
    assert report.final_time == result.duration
    assert GEERING_OPTIMUM * 0.998 <= report.final_time <= GEERING_OPTIMUM * 1.01
    assert report.statistics.complete and report.statistics.best_grid_time == report.tubes[0].time
    chosen = report.tubes[report.chosen_tube]
    assert chosen.points[0] == pytest.approx([0.0, 0.0])
    # the goal, or a revolution of a joint away from it
    assert np.remainder(chosen.points[-1] - goal + np.pi, 2 * np.pi) - np.pi == pytest.approx([0.0, 0.0], abs=1e-9)
    assert np.all(report.low <= chosen.points.min(axis=0)) and np.all(chosen.points.max(axis=0) <= report.high)
    (local,) = report.local
    assert local.grid_time == report.tubes[0].time
    assert local.time <= local.seed_time and local.time == pytest.approx(report.final_time, rel=1e-3)
    assert len(local.control_points) == len(local.round_times) >= 1
