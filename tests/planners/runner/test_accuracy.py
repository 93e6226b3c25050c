"""Accuracy as stated: the default phase_plane answer is at most 0.1 % above the converged
time-optimal duration (TOPP-RA on 20,000 intervals), on seeded random spline paths of ur5,
panda and the two-link paper arms. ``benchmarks/accuracy.py`` runs the larger study."""

from __future__ import annotations

import re

import numpy as np
import pytest

from benchmarks.accuracy import KINDS, converged_duration, random_waypoints, recorded_waypoints
from benchmarks.converged import converged_duration as converged
from benchmarks.converged import random_path
from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.generators.joint_moves import Unsynchronized, ViaPoints
from toptraj.planners.paths import SplinePath
from toptraj.planners.timing.min_cost import MinCostMethod
from toptraj.service.problems import note_text


@pytest.mark.parametrize("name", ["ur5", "panda", "geering_2r", "yamamoto_2r"])
def test_default_durations_are_within_a_tenth_of_a_percent_of_the_converged_optimum(name):
    robot = robots.load(name)
    rng = np.random.default_rng(7)
    compared = 0
    for _ in range(3):
        waypoints = random_waypoints(robot, rng)
        try:
            reference = converged_duration(robot, waypoints)
        except InfeasiblePath:
            continue
        result = plan(build_problem(robot, WaypointPath(waypoints), METHODS["phase_plane"], limits=LimitRequest(kinds=KINDS), sampling=Sampling(dt=0.01)))
        # Both are conservative discretizations of the same problem: the refined grid may
        # come out a hair below the 20,000-interval one, never far.
        assert 0.9995 <= result.duration / reference <= 1.001, (waypoints.tolist(), result.duration, reference)
        compared += 1
    assert compared >= 2


# Every answer states its accuracy (planners/runner/accuracy.py): the estimated relative gap to the
# converged optimum, held within 0.1 % for time-optimal methods on their default grids.

UR5_START = [0.3, -1.6, 1.7, -1.6, -1.57, 0.2]
#: The weld seam of the README: ur5's tool along a straight line at 5 cm/s.
WELD_LINE = {"kind": "cartesian", "start": UR5_START, "positions": [[0.413, 0.542, 0.286]]}


def _weld(client, method: str, **timing) -> dict:
    body = {
        "robot": "ur5",
        "path": WELD_LINE,
        "timing": {"method": method, "constraints": list(KINDS), "limits": {"tool_speed": 0.05}, **timing},
        "output": {"dt": 0.05},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    return response.json()


@pytest.fixture(scope="module")
def weld_reference(client) -> float:
    """The weld line's converged time-optimal duration: TOPP-RA on 20,000 intervals (its own
    discretization error there is about 1e-5)."""
    return _weld(client, "toppra", grid_points=20_000)["duration"]


def _gap_warnings(body: dict) -> list[str]:
    return [text for text in body["warnings"] if "of the time-optimal one" in text]


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
def test_the_weld_line_is_held_within_a_tenth_of_a_percent_and_says_how_close(client, weld_reference, method):
    """Before: 1.8 % above the converged optimum on the default grid of 100 intervals, without a
    word. Now the default answer is within 0.1 % of it, and its stated gap is the true one."""
    body = _weld(client, method)
    true_gap = body["duration"] / weld_reference - 1.0
    assert true_gap <= 1e-3
    stated = body["accuracy"]["relative_gap"]
    assert stated is not None and "phase-plane method" in body["accuracy"]["basis"]
    assert abs(stated - abs(true_gap)) <= 1e-4, (stated, true_gap)
    assert not _gap_warnings(body)


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
def test_a_named_grid_keeps_its_grid_and_warns_with_a_remedy_that_works(client, weld_reference, method):
    """timing.grid_points 100: the request's grid, its 1.8 % stated in the accuracy and in a
    warning, whose grid_points advice (within what the method serves) holds the 0.1 %."""
    body = _weld(client, method, grid_points=100)
    true_gap = body["duration"] / weld_reference - 1.0
    assert 0.015 < true_gap < 0.021  # the grid is kept: the 1.8 %
    assert body["accuracy"]["relative_gap"] == pytest.approx(true_gap, rel=0.02)
    (warning,) = _gap_warnings(body)
    assert "1.8 %" in warning
    advised = int(re.search(r"timing\.grid_points (\d+) would", warning).group(1))
    assert 100 < advised <= MinCostMethod().max_grid_intervals(6)
    followed = _weld(client, method, grid_points=advised)
    assert followed["duration"] / weld_reference - 1.0 <= 1e-3
    assert not _gap_warnings(followed)


def test_min_cost_on_a_recorded_path_is_within_a_tenth_of_a_percent():
    """A recorded ur5 path with tiny first steps: min_cost came out 0.16 % above the converged
    optimum without a warning; now within 0.1 %, with a stated gap close to the true one.
    (Without a time budget: under a budget the refinement is done only when the budget left
    holds it, else the answer warns.)"""
    robot = robots.load("ur5")
    waypoints = recorded_waypoints(robot, np.random.default_rng(0), 5)
    reference, _ = converged(SplinePath(waypoints), robot)
    result = plan(build_problem(robot, WaypointPath(waypoints, min_spacing=0.0), METHODS["min_cost"], limits=LimitRequest(kinds=KINDS), sampling=Sampling(dt=0.05)))
    true_gap = result.duration / reference - 1.0
    assert -1e-4 <= true_gap <= 1e-3
    assert result.accuracy is not None
    assert result.accuracy.relative_gap == pytest.approx(abs(true_gap), abs=1e-4)


def test_min_cost_s_finer_grid_counts_its_set_up_once_against_the_budget():
    """A torque-bound ur5 path on min_cost's 100 intervals (7.8 % above the optimum): its solve
    under a server's budget took 0.24 s, 0.05 s of it the worker process (``fixed_seconds``)
    and most of the rest cvxpy's set-up, and was scaled by the grid's growth (41 fold, to 4,096
    intervals) as if all of it grew: 9.8 s, three times which the 19.7 s left did not hold, so
    the answer stayed 7.8 % above the optimum. Counted as the method's set-up
    (``setup_intervals``), the finer solve is expected to take 3.4 s (it takes about 3.5 s) and
    is done."""
    import dataclasses

    from toptraj.planners.checks.accuracy import finer_constraints
    from toptraj.planners.constraints.path_constraints import build_path_constraints
    from toptraj.planners.execution.deadline import Deadline
    from toptraj.planners.paths.grid import path_grid
    from toptraj.planners.timing.min_cost import CostTimeScaling

    arm = robots.load("ur5")
    path = SplinePath(np.array([[0, -1.2, 1, 0, 0.5, 0], [0.8, -0.3, 0.4, -0.5, 0.9, 0.3]], dtype=float))
    constraints = build_path_constraints(path, arm, arm.limits, ("torque",), path_grid(path, 100))
    result = CostTimeScaling(constraints.s, np.ones(101), optimality_gap=0.078, fixed_seconds=0.05)
    finer = path_grid(path, 4096)
    method = MinCostMethod()
    refined = finer_constraints(method, constraints, result, finer, 0.24, Deadline(19.7), False)
    assert refined is not None and len(refined.s) > 4097  # the 4,096 intervals beside the 100
    # the estimate as it was, everything scaled by the grid's growth: refused
    unset = dataclasses.replace(result, fixed_seconds=0.0)
    monkey = type("Method", (MinCostMethod,), {"setup_intervals": 0})()
    assert finer_constraints(monkey, constraints, unset, finer, 0.24, Deadline(19.7), False) is None


@pytest.mark.parametrize("name", ["ur5", "geering_2r"])
@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
def test_the_stated_gap_of_a_spline_matches_the_converged_reference(name, method):
    """Seeded spline paths: the stated gap is within 1e-4 of the true one (against the
    Richardson-converged reference of ``benchmarks/converged.py``) or above it, and no answer
    is more than 0.1 % above the reference without a warning."""
    robot = robots.load(name)
    waypoints, path = random_path(robot, np.random.default_rng(3))
    reference, _ = converged(path, robot)
    result = plan(build_problem(robot, WaypointPath(waypoints), METHODS[method], limits=LimitRequest(kinds=KINDS), sampling=Sampling(dt=0.01)))
    true_gap = result.duration / reference - 1.0
    assert result.accuracy is not None and result.accuracy.relative_gap is not None
    assert result.accuracy.relative_gap >= abs(true_gap) - 1e-4, (result.accuracy, true_gap)
    assert result.accuracy.relative_gap <= abs(true_gap) + 6e-4, (result.accuracy, true_gap)
    assert true_gap <= 1e-3 or any("time-optimal" in text for text in result.warnings)


def test_min_cost_with_a_torque_weight_states_its_cost_gap():
    """beta > 0: the cost's gap, estimated on half the grid, bounds the true one (against the
    cost on a grid four times finer, converged within the solver's own 5e-6) without
    overstating it more than a few times (the scheme converges faster than first order here)."""
    robot = robots.load("geering_2r")
    waypoints = np.array([[0.0, 0.0], [1.0, 0.6], [1.6, -0.4]])
    timing = dict(method=MinCostMethod(0.01), limits=LimitRequest(kinds=KINDS))
    result = plan(build_problem(robot, WaypointPath(waypoints), **timing, sampling=Sampling(dt=0.01)))
    fine = plan(build_problem(robot, WaypointPath(waypoints), **timing, grid=800, sampling=Sampling(dt=0.01)))
    true_gap = result.cost / fine.cost - 1.0
    assert result.accuracy is not None and "half the intervals" in result.accuracy.basis
    assert 1e-5 < true_gap <= result.accuracy.relative_gap <= 5.0 * true_gap


def test_every_answer_carries_an_accuracy_field_and_the_schema_documents_it(client):
    """The typical request states phase_plane's own estimate; a time law of a requested
    duration says it has none;
    compare entries carry it; the OpenAPI schema documents it."""
    body = client.post("/v1/trajectories", json={
        "robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "output": {"dt": 0.05},
    }).json()
    assert 0.0 <= body["accuracy"]["relative_gap"] <= 6e-4
    assert "midpoint" in body["accuracy"]["basis"]
    law = client.post("/v1/trajectories", json={
        "robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
        "timing": {"method": "quintic", "duration": 3.0}, "output": {"dt": 0.05},
    }).json()
    assert law["accuracy"]["relative_gap"] is None and "not estimated" in law["accuracy"]["basis"]
    compared = client.post("/v1/trajectories/compare", json={
        "robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "methods": ["phase_plane", "toppra"],
    }).json()
    assert all(entry["accuracy"]["relative_gap"] is not None for entry in compared["results"])
    schema = client.get("/openapi.json").json()["components"]["schemas"]
    assert "relative_gap" in schema["AccuracyPublic"]["properties"]
    assert "accuracy" in schema["TrajectoryResponse"]["required"]


@pytest.mark.parametrize("method", ["quintic", "cycloidal"])
def test_a_time_law_states_its_gap_to_its_own_shortest_duration(method):
    """A time law at its shortest: the stated gap g puts the law's own shortest duration at
    T / (1 + g); the same law asked for that duration (plus 1e-4) holds the limits, and for
    0.2 % less does not."""
    robot = robots.load("ur5")
    path = WaypointPath(np.array(UR5_WAYPOINTS))
    result = plan(build_problem(robot, path, METHODS[method], limits=LimitRequest(kinds=KINDS), sampling=Sampling(dt=0.01)))
    gap = result.accuracy.relative_gap
    assert gap is not None and "peak utilization" in result.accuracy.basis
    shortest = result.duration / (1.0 + gap)
    held = plan(build_problem(robot, path, METHODS[method], limits=LimitRequest(kinds=KINDS), duration=shortest * (1 + 1e-4), sampling=Sampling(dt=0.01)))
    assert max(float(np.max(peak)) for peak in held.peak_utilization.values()) == pytest.approx(1.0, abs=1.5e-3)
    with pytest.raises(InfeasiblePath):
        plan(build_problem(robot, path, METHODS[method], limits=LimitRequest(kinds=KINDS), duration=shortest * (1 - 2e-3), sampling=Sampling(dt=0.01)))


def test_the_typical_request_states_its_accuracy_without_a_second_solve(monkeypatch):
    """phase_plane's estimate is its own refinement's: the typical request (4 ur5 waypoints)
    solves once."""
    from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

    calls = []
    solve = PhasePlaneMethod.solve
    monkeypatch.setattr(PhasePlaneMethod, "solve", lambda self, *args, **kwargs: calls.append(1) or solve(self, *args, **kwargs))
    result = plan(build_problem(robots.load("ur5"), WaypointPath(np.array(UR5_WAYPOINTS)), METHODS["phase_plane"], sampling=Sampling(dt=0.01)))
    assert len(calls) == 1
    assert result.accuracy is not None and 0.0 <= result.accuracy.relative_gap <= 6e-4


def test_the_warning_advises_only_what_the_method_serves():
    """The remedy of a gap above 0.1 % is a timing.grid_points the method serves on the robot
    (the gap shrinks as the intervals grow), else the phase-plane method, never a grid beyond
    its cap."""
    from toptraj.planners.runner.accuracy import gap_warning
    from toptraj.planners.timing.toppra_method import ToppraMethod

    within = gap_warning(ToppraMethod(), 0.008, 100, 6, grid_given=True)
    assert (within.facts["remedy"], within.facts["wanted"], within.facts["gap"]) == ("grid.intervals", 1000, 0.008)
    assert within.facts["wanted"] <= within.facts["cap"]
    assert "0.8 %" in note_text(within) and "timing.grid_points 1000 would bring it within 0.1 %" in note_text(within)
    cap = MinCostMethod().max_grid_intervals(7)
    beyond = gap_warning(MinCostMethod(), 0.01, 2000, 7, grid_given=True)
    assert (beyond.facts["remedy"], beyond.facts["wanted"], beyond.facts["cap"]) == ("method", None, cap)
    text = note_text(beyond)
    assert "timing.grid_points" not in text.split(":")[-1] and "phase_plane" in text and str(cap) in text
    refined = gap_warning(ToppraMethod(), 0.003, 400, 6, grid_given=False)
    assert (refined.facts["remedy"], refined.facts["grid_given"]) == ("method", False)
    text = note_text(refined)
    assert "1 %" not in text and "0.3 %" in text and text.endswith("timing.method phase_plane refines its grid where the error lies")


def test_the_joint_trajectory_format_carries_the_accuracy(client):
    body = client.post("/v1/trajectories", json={
        "robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
        "output": {"dt": 0.05, "format": "joint_trajectory"},
    }).json()
    assert "joint_trajectory" in body and body["accuracy"]["relative_gap"] is not None


def test_a_finer_grid_that_breaks_a_limit_leaves_the_default_answer_with_a_warning():
    """A recorded ur5 path where toppra on the refined grid exceeds an acceleration limit
    between grid points: the answer on the default grid, which holds the limits, stands, with
    its stated gap (close to the true 0.29 %) and a warning that gives it."""
    robot = robots.load("ur5")
    rng = np.random.default_rng(1)
    for _ in range(10):
        waypoints = recorded_waypoints(robot, rng, 5)
    reference, _ = converged(SplinePath(waypoints), robot)
    result = plan(build_problem(robot, WaypointPath(waypoints, min_spacing=0.0), METHODS["toppra"], limits=LimitRequest(kinds=KINDS), sampling=Sampling(dt=0.05)))
    true_gap = result.duration / reference - 1.0
    assert true_gap > 1e-3
    assert result.accuracy is not None and result.accuracy.relative_gap == pytest.approx(true_gap, abs=1e-4)
    (warning,) = [text for text in result.warnings if "of the time-optimal one" in text]
    assert (warning.rule, warning.facts["gap"], warning.facts["remedy"]) == ("gap_above_target", result.accuracy.relative_gap, "method")
    assert f"{100 * result.accuracy.relative_gap:.2g} %" in note_text(warning) and "phase_plane" in note_text(warning)


@pytest.mark.parametrize(
    "interpolation, law, synchronization",
    [("via", "cubic", "normalized"), ("via", "quintic", "normalized"), ("linear", "trapezoidal", "none"), ("linear", "quintic", "none")],
)
def test_time_laws_through_via_points_or_joint_by_joint_state_their_gap(interpolation, law, synchronization):
    """Through via points (each segment at its shortest) and joint by joint (each joint's law
    at its shortest), the answer states its gap to the shortest uniform speed-up of its
    profile: about zero, since its most used limit binds (peak utilization 1)."""
    arm = robots.load("ur5")
    waypoints = np.array(UR5_WAYPOINTS[:3] if interpolation == "via" else UR5_WAYPOINTS[:2])
    method = Unsynchronized(METHODS[law]) if synchronization == "none" else ViaPoints(METHODS[law])
    limits = LimitRequest(kinds=("velocity", "acceleration"))
    result = plan(build_problem(arm, WaypointPath(waypoints, interpolation), method, limits=limits, sampling=Sampling(dt=0.05)))
    assert result.accuracy.relative_gap is not None
    assert result.accuracy.relative_gap <= 1e-6
    assert "peak utilization" in result.accuracy.basis
    binding = max(float(result.peak_utilization[kind].max()) for kind in ("velocity", "acceleration"))
    assert binding == pytest.approx(1.0, abs=1e-3)
