"""Jerk-limited ruckig moves, via-point trajectories and the method comparison endpoint."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.generators.joint_moves import ViaPoints

UR5 = robots.load("ur5")
START = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])


def test_ruckig_long_move_closed_form():
    """One joint, L = 2 rad with v = 1, a = 2, j = 10 (cruise reached): T = L/v + v/a + a/j."""
    goal = START + np.array([2.0, 0, 0, 0, 0, 0])
    timing = dict(method=METHODS["ruckig"], limits=LimitRequest(kinds=("velocity", "acceleration", "jerk"), overrides={"velocity": [1.0] * 6, "acceleration": [2.0] * 6, "jerk": [10.0] * 6}))
    result = plan(build_problem(UR5, WaypointPath(np.array([START, goal])), **timing))
    assert result.duration == pytest.approx(2.0 / 1.0 + 1.0 / 2.0 + 2.0 / 10.0, rel=1e-9)
    for kind in ("velocity", "acceleration", "jerk"):
        assert result.peak_utilization[kind].max() == pytest.approx(1.0, abs=2e-3)
    assert result.samples.q[-1] == pytest.approx(goal, abs=1e-9)
    # the closed form is its method's optimum: the answer states so
    assert result.accuracy.relative_gap == 0.0
    assert "exact" in result.accuracy.basis


def test_ruckig_is_never_faster_than_time_optimal():
    path = WaypointPath(np.array(UR5_WAYPOINTS[:2]))
    jerky = plan(build_problem(UR5, path, METHODS["ruckig"], limits=LimitRequest(kinds=("velocity", "acceleration", "jerk"))))
    optimal = plan(build_problem(UR5, path, METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration"))))
    assert jerky.duration >= optimal.duration
    assert jerky.peak_utilization["jerk"].max() <= 1.005


def test_ruckig_needs_two_waypoints(client):
    body = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "timing": {"method": "ruckig", "constraints": ["velocity", "jerk"]}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422
    assert "exactly 2 waypoints" in response.json()["detail"] and "no intermediate waypoints" in response.json()["detail"]


@pytest.mark.parametrize("law", ["cubic", "quintic"])
def test_via_points(law):
    """Through every waypoint, continuous velocity (and acceleration for the quintic), every
    limit held, at rest at both ends."""
    waypoints = np.array(UR5_WAYPOINTS)
    result = plan(build_problem(UR5, WaypointPath(waypoints, "via"), ViaPoints(METHODS[law]), sampling=Sampling(dt=0.0005)))
    samples = result.samples
    for waypoint in waypoints[1:-1]:
        assert np.min(np.linalg.norm(samples.q - waypoint, axis=1)) < 0.5 * 0.0005 * np.abs(samples.qd).max() * 3
    assert samples.qd[0] == pytest.approx(np.zeros(6), abs=1e-12) and samples.qd[-1] == pytest.approx(np.zeros(6), abs=1e-9)
    max_jump = np.abs(np.diff(samples.qd, axis=0)).max()
    assert max_jump <= 0.0005 * UR5.limits.acceleration.max() * 1.01  # no velocity step
    if law == "quintic":
        assert np.abs(np.diff(samples.qdd, axis=0)).max() <= 0.0005 * UR5.limits.jerk.max()
    for kind in ("velocity", "acceleration", "torque"):
        assert result.peak_utilization[kind].max() <= 1.005
    assert max(result.peak_utilization[kind].max() for kind in ("velocity", "acceleration", "torque")) >= 0.99


def test_compare_endpoint(client):
    body = {
        "robot": "ur5",
        "path": {"waypoints": UR5_WAYPOINTS},
        "methods": ["phase_plane", "toppra", "quintic", "trapezoidal", "ruckig"],
        "timing": {"constraints": ["velocity", "acceleration", "torque"]},
    }
    response = client.post("/v1/trajectories/compare", json=body)
    assert response.status_code == 200, response.text
    results = {row["method"]: row for row in response.json()["results"]}
    assert results["phase_plane"]["duration"] <= results["toppra"]["duration"] * (1 + 1e-9)
    assert results["phase_plane"]["duration"] < results["trapezoidal"]["duration"] < results["quintic"]["duration"]
    assert results["quintic"]["binding"]["kind"] in ("velocity", "acceleration", "torque")
    assert results["ruckig"]["error"]["status"] == 422
    for method in ("phase_plane", "toppra", "quintic", "trapezoidal"):
        assert max(max(values) for values in results[method]["peak_utilization"].values() if values) <= 1.005
        assert results[method]["solve_ms"] > 0


def test_ruckig_with_jerk_alone():
    """ruckig always limits jerk, even when the request lists no limit at all."""
    path = WaypointPath(np.array(UR5_WAYPOINTS[:2]))
    result = plan(build_problem(UR5, path, METHODS["ruckig"], limits=LimitRequest(kinds=())))
    assert result.peak_utilization["jerk"].max() == pytest.approx(1.0, abs=5e-3)
