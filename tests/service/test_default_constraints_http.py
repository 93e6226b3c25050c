"""``timing.constraints`` left out: the default kinds (velocity, acceleration, torque) that the
method holds, and a warning naming the default kind it cannot hold with that kind's peak; a kind
asked for that the method cannot hold stays a 422 that says how to fix it."""

from __future__ import annotations

import ast
import re

import numpy as np
import pinocchio as pin
import pytest

from tests.paths import ROOT
from toptraj import robots

W = {"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]]}


@pytest.fixture(scope="module")
def ruckig_default(client):
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": W, "timing": {"method": "ruckig"}, "output": {"dt": 0.002}})
    assert response.status_code == 200, response.text
    return response.json()


def test_ruckig_without_constraints_holds_its_defaults_and_says_torque_is_not_held(ruckig_default):
    limits = robots.load("ur5").limits
    samples = ruckig_default["samples"]
    qd, qdd = np.array(samples["qd"]), np.array(samples["qdd"])
    assert (np.abs(qd).max(axis=0) / limits.velocity).max() <= 1.005
    assert (np.abs(qdd).max(axis=0) / limits.acceleration).max() <= 1.005
    [note] = [note for note in ruckig_default["warnings"] if "torque limits are not held" in note]
    # The peak stated is the torque's, recomputed here from the samples by inverse dynamics.
    robot = robots.load("ur5")
    data = robot.model.createData()
    tau = np.array([pin.rnea(robot.model, data, q, v, a) for q, v, a in zip(np.array(samples["q"]), qd, qdd)])
    peak = np.abs(tau).max(axis=0) / limits.torque
    joint = int(np.argmax(peak))
    stated = re.search(r"the torque peaks at ([0-9.]+) times the limit", note)
    assert stated is not None, note
    assert float(stated.group(1)) == pytest.approx(peak[joint], rel=0.01)
    assert f"of joint {robot.joint_names[joint]!r}" in note
    assert "timing.method 'jerk_limited'" in note and "timing.method 'ruckig' holds only velocity, acceleration, jerk" in note


def test_torque_asked_of_ruckig_is_refused_with_the_fix(client):
    body = {"robot": "ur5", "path": W, "timing": {"method": "ruckig", "constraints": ["velocity", "acceleration", "torque"]}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422
    detail = response.json()["detail"]
    assert "drop 'torque' from timing.constraints (e.g. ['velocity', 'acceleration'])" in detail
    assert "timing.method 'jerk_limited', which holds torque and jerk" in detail
    # Both remedies, followed, are answered.
    for timing in ({"method": "ruckig", "constraints": ["velocity", "acceleration"]}, {"method": "jerk_limited", "constraints": ["velocity", "acceleration", "torque", "jerk"]}):
        assert client.post("/v1/trajectories", json={**body, "timing": timing}).status_code == 200, timing


def test_the_compare_example_of_the_client_guide_answers_every_method(client):
    guide = (ROOT / "docs" / "client.md").read_text()
    waypoints = ast.literal_eval(re.search(r"^waypoints = (\[.*?\]\])$", guide, re.M | re.S).group(1))
    call = re.search(r'toptraj\.compare\("ur5", waypoints(\[:2\])?, methods=(\[.*?\])\)', guide)
    assert call is not None and call.group(1) == "[:2]"  # ruckig moves between two waypoints
    methods = ast.literal_eval(call.group(2))
    assert "ruckig" in methods
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": waypoints[:2]}, "methods": methods}
    response = client.post("/v1/trajectories/compare", json=body)
    assert response.status_code == 200, response.text
    results = response.json()["results"]
    assert [item["method"] for item in results] == body["methods"]
    assert all(item.get("error") is None and item["duration"] > 0 for item in results), results


def test_default_constraints_of_a_torque_method_are_unchanged(client):
    given = {"robot": "ur5", "path": W, "timing": {"constraints": ["velocity", "acceleration", "torque"]}}
    left_out = {"robot": "ur5", "path": W}
    first, second = (client.post("/v1/trajectories", json=body).json() for body in (given, left_out))
    assert first["duration"] == second["duration"]
    assert not [note for note in second["warnings"] if "not held" in note]
