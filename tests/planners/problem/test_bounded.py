"""A motion that no limit held bounds is refused before planning, with what bounds it: the paper
arms have torque limits only, so velocity or acceleration limits alone left the phase plane's
maximum velocity curve infinite (a division by zero in the timing, worded as a numerical
breakdown) and a cell timed at 0.2 ms with torques of 1e7 N m (a 200)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from fastapi.testclient import TestClient

from toptraj import robots
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.problem.bounded import check_speed_bounded
from toptraj.service.app import create_app
from toptraj.service.settings import Settings


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with TestClient(create_app(Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("bounded")))) as test_client:
        yield test_client


def _trajectory(constraints, method="phase_plane", **limits) -> dict:
    timing = {"method": method, "constraints": constraints} | ({"limits": limits} if limits else {})
    return {"robot": "geering_2r", "path": {"waypoints": [[0.0, 0.0], [1.0, 1.0]]}, "timing": timing}


@pytest.mark.parametrize("method", ["phase_plane", "toppra", "quintic", "jerk_limited"])
@pytest.mark.parametrize("constraints", [["velocity"], ["acceleration"], ["velocity", "acceleration"]])
def test_limits_the_robot_does_not_have_are_refused_naming_what_bounds_it(client, method, constraints):
    response = client.post("/v1/trajectories", json=_trajectory(constraints, method))
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert detail.startswith(f"nothing bounds the motion of geering_2r: it has no finite {constraints[0]}"), detail
    assert "add 'torque' to timing.constraints (geering_2r has finite limits of that kind)" in detail
    assert f'give the limits in timing.limits, e.g. "{constraints[0]}": one value per joint in rad/s' in detail


def test_either_remedy_plans_the_motion(client):
    with_torque = client.post("/v1/trajectories", json=_trajectory(["velocity", "torque"]))
    assert with_torque.status_code == 200 and with_torque.json()["duration"] == pytest.approx(1.2654, abs=1e-3)
    given = client.post("/v1/trajectories", json=_trajectory(["velocity"], velocity=[2.0, 2.0]))
    assert given.status_code == 200, given.text
    # 1 rad at 2 rad/s: 0.5 s, and on the grid of 100 intervals the first and last take twice
    # their time at full speed (x = sd^2 linear in s from rest), 0.01 s more
    assert given.json()["duration"] == pytest.approx(0.51, abs=1e-6)
    assert max(given.json()["peak_utilization"]["velocity"]) == pytest.approx(1.0, abs=5e-3)


def test_a_cell_of_arms_without_the_limits_asked_is_refused_and_with_torque_is_planned(client):
    arm = {"robot": "yamamoto_2r", "waypoints": [[0.0, 0.0], [1.0, 1.0]]}
    cell = {"arms": [arm, {**arm, "base": {"position": [3.0, 0.0, 0.0]}}], "constraints": ["velocity"]}
    refused = client.post("/v1/cells", json=cell)
    assert refused.status_code == 422, refused.text[:300]
    assert refused.json()["detail"] == (
        "arms[0]: nothing bounds the motion of yamamoto_2r: it has no finite velocity limit, so the shortest time would be "
        "zero; add 'torque' to constraints (yamamoto_2r has finite limits of that kind)"
    )
    planned = client.post("/v1/cells", json={**cell, "constraints": ["velocity", "torque"]})
    assert planned.status_code == 200, planned.text[:300]
    assert planned.json()["duration"] > 0.1
    assert max(planned.json()["arms"][0]["peak_utilization"]["torque"]) == pytest.approx(1.0, abs=5e-3)


def test_a_segment_that_moves_only_joints_without_a_limit_is_refused_naming_it():
    robot = robots.load("geering_2r")
    limits = dataclasses.replace(robot.limits, velocity=np.array([2.0, np.inf]))
    check_speed_bounded(robot, limits, ("velocity",), np.array([[0.0, 0.0], [1.0, 1.0]]))  # phi moves throughout
    with pytest.raises(InvalidRequest) as raised:
        check_speed_bounded(robot, limits, ("velocity",), np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))
    assert (raised.value.rule, raised.value.segment, raised.value.joints) == ("segment_unbounded", 1, ("psi",))
    check_speed_bounded(robot, limits, ("velocity", "torque"), np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))
