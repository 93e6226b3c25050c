"""The answer's ``solver``, ``switching_times`` and ``search`` bodies, built by the service from
the library's typed reports (``toptraj.service.reports``): every field in place, and the
non-finite numbers (no speed bound, no timing of a seed) written as null."""

from __future__ import annotations

import math

import numpy as np

from toptraj.planners.generators.collocation.report import CollocationReport
from toptraj.planners.generators.search.outcome import GridPath, SearchStatistics
from toptraj.planners.generators.search.report import LocalReport, SearchReport
from toptraj.planners.trajectory import SwitchingTimes
from toptraj.service.reports import search_body, solver_body, switching_body


def _collocation(switching):
    return CollocationReport(0.55, 0.21, "IPOPT: Solve_Succeeded", 42, "straight", 1.5, switching, 2e-7, "second integration")


def test_solver_body_names_the_switching_of_a_minimum_time_collocation_only():
    assert solver_body(_collocation("refined")) == {
        "cost": 0.55, "duration": 0.21, "status": "IPOPT: Solve_Succeeded", "iterations": 42, "initial_guess": "straight",
        "solve_s": 1.5, "switching": "refined", "optimality_gap": 2e-7, "gap_basis": "second integration",
    }
    assert "switching" not in solver_body(_collocation(None))
    assert solver_body(None) is None


def test_switching_body_per_joint_name():
    times = SwitchingTimes(("phi", "psi"), (np.array([0.19, 0.4878, 0.785]), np.array([0.4878])))
    body = switching_body(times)
    assert body == {"phi": [0.19, 0.4878, 0.785], "psi": [0.4878]}
    assert all(type(t) is float for ts in body.values() for t in ts)
    assert times.of("psi").tolist() == [0.4878]
    assert switching_body(None) is None


def test_search_body_from_the_typed_report():
    statistics = SearchStatistics("lattice", 25, 72, [5, 5], 300, 4, 2, math.inf, expanded=10, best_grid_time=1.0151, upper_bound=math.inf)
    tube = GridPath(np.array([[0.0, 0.0], [0.38, 0.0], [0.76, 0.0]]), 1.0151, (0.5, 0.7, 0.9))
    local = LocalReport(1.0151, math.inf, 0.98, (4, 5), (0.99, math.nan), 321, "converged", 0.25)
    report = SearchReport(statistics, 0.3, (tube,), 0, np.array([-0.1, -0.2]), np.array([0.9, 0.2]), None, (local,), 0.98)
    body = search_body(report)
    assert body["v_max"] is None and body["upper_bound"] is None and body["best_grid_time"] == 1.0151
    assert body["pruned"] == {"t1": 0, "t2": 0, "t3": 0, "t4": 0, "t_u": 0}
    assert body["grid_shape"] == [5, 5] and body["expanded"] == 10 and body["goal_variants"] == 1
    assert body["tubes"] == [{"time": 1.0151, "t1": 0.5, "t2": 0.7, "t3": 0.9, "points": [[0.0, 0.0], [0.38, 0.0], [0.76, 0.0]]}]
    assert body["chosen_tube"] == 0 and body["tube_radius"] == 0.3
    assert body["region"] == {"lower": [-0.1, -0.2], "upper": [0.9, 0.2]}
    assert body["shadows"] is None and body["final_time"] == 0.98
    assert body["local"] == [{
        "grid_time": 1.0151, "seed_time": None, "time": 0.98, "control_points": [4, 5], "round_times": [0.99, None],
        "evaluations": 321, "stopped": "converged", "wall_s": 0.25,
    }]
    assert search_body(None) is None
