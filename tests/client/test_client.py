"""The Python client: typed results equal to the HTTP answers, problems as ProblemError."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj.client import Client, ProblemError


@pytest.fixture(scope="module")
def toptraj(client):
    return Client(http=client)


def test_plan_returns_the_samples_as_arrays(toptraj, client):
    trajectory = toptraj.plan("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration"])
    body = client.post(
        "/v1/trajectories",
        json={"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "timing": {"constraints": ["velocity", "acceleration"]}},
    ).json()
    assert trajectory.duration == body["duration"] and trajectory.method == "phase_plane"
    np.testing.assert_array_equal(trajectory.q, np.array(body["samples"]["q"]))
    assert trajectory.q.shape == (len(trajectory.t), 6) and trajectory.tau.shape == trajectory.q.shape


def test_compare_and_robots(toptraj):
    results = toptraj.compare("ur5", UR5_WAYPOINTS, methods=["phase_plane", "quintic"])
    assert [r.method for r in results] == ["phase_plane", "quintic"]
    assert results[0].duration < results[1].duration
    assert "ur5" in {robot["name"] for robot in toptraj.robots()}
    assert toptraj.robot("ur5")["dof"] == 6


def test_a_problem_is_raised_with_its_facts(toptraj):
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("ur5", [[0.0] * 6, [9.0] + [0.0] * 5])
    assert caught.value.status == 422 and "outside the limits" in caught.value.detail
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("nope", [[0.0], [1.0]])
    assert caught.value.status == 404


def test_plan_in_background_runs_a_job_and_returns_its_answer(toptraj, client):
    """A request as a job: submitted, polled, and returned as the synchronous answer would be;
    a job's problem is raised with the synchronous endpoint's facts."""
    request = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "timing": {"constraints": ["velocity"]}}
    trajectory = toptraj.plan_in_background(request, budget_s=60, poll_s=0.05)
    body = client.post("/v1/trajectories", json=request).json()
    assert trajectory.duration == body["duration"]
    np.testing.assert_array_equal(trajectory.q, np.array(body["samples"]["q"]))
    impossible = {**request, "path": {"kind": "waypoints", "waypoints": [[0.0] * 6, [9.0] + [0.0] * 5]}}
    with pytest.raises(ProblemError) as caught:
        toptraj.plan_in_background(impossible, budget_s=60, poll_s=0.05)
    assert caught.value.status == 422 and "outside the limits" in caught.value.detail
