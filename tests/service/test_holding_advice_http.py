"""A path that no motion can follow within the torque limits, not even at rest: the 422 names
every such stretch with what holding still needs there against the limit (recomputed here by
an independent RNEA at rest), and a remedy that, followed, is answered."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots

START, GOAL = [0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]
W = {"kind": "waypoints", "waypoints": [START, GOAL]}


def _gravity(q):
    robot = robots.load("ur5")
    return pin.rnea(robot.model, robot.model.createData(), np.array(q, dtype=float), np.zeros(6), np.zeros(6))


@pytest.fixture(scope="module")
def refused(client):
    body = {"robot": "ur5", "path": W, "timing": {"limits": {"torque_scale": 0.2}}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422
    return body, response.json()


def test_the_refusal_gives_the_figures_of_holding_still(refused):
    _, problem = refused
    detail = problem["detail"]
    goal, start = _gravity(GOAL), _gravity(START)
    # The ur5 has no friction: holding still needs gravity's torque, here on the shoulder lift.
    assert f"holding still needs {abs(goal[1]):.4g} N m on joint 'shoulder_lift_joint' (at s = 1.0000) against its limit of 30 N m" in detail
    assert f"holding still at s = 0 needs {abs(start[1]):.4g} N m on joint 'shoulder_lift_joint' against its limit of 30 N m" in detail
    assert abs(start[1]) == pytest.approx(31.16, abs=0.005)
    assert problem["joint"] == "shoulder_lift_joint" and problem["limit"] == "torque"
    assert re.search(r"on 1 stretch\(es\): s = 0\.\d{4} to 1\.0000", detail), detail


def test_the_remedies_followed_are_answered(client, refused):
    body, problem = refused
    detail = problem["detail"]
    scale = float(re.search(r"timing\.limits\.torque_scale ([0-9.]+)", detail).group(1))
    exact = 0.2 * abs(_gravity(GOAL)[1]) / 30  # the scale at which gravity's hold at the goal is the limit
    assert exact < scale <= exact * 1.001 + 1e-3  # rounded up to 3 digits with a little room
    followed = client.post("/v1/trajectories", json={**body, "timing": {"limits": {"torque_scale": scale}}})
    assert followed.status_code == 200, followed.text
    limit = float(re.search(r"timing\.limits\.torque of ([0-9.]+) N m on joint 'shoulder_lift_joint'", detail).group(1))
    torque = [150, limit, 150, 28, 28, 28]
    followed = client.post("/v1/trajectories", json={**body, "timing": {"limits": {"torque_scale": 0.2, "torque": torque}}})
    assert followed.status_code == 200, followed.text


def test_a_vertical_axis_holding_no_gravity_is_not_blamed(client):
    """At torque_scale 0.1 the shoulder lift and the elbow cannot hold the path; the base's
    vertical axis holds no gravity torque anywhere (RNEA at rest: 0), so it is not named."""
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": W, "timing": {"limits": {"torque_scale": 0.1}}})
    assert response.status_code == 422
    detail = response.json()["detail"]
    for s in np.linspace(0.0, 1.0, 11):
        assert abs(_gravity(np.add(START, s * np.subtract(GOAL, START)))[0]) < 1e-9
    assert "shoulder_pan_joint" not in detail, detail
    elbow = max(abs(_gravity(q)[2]) for q in (START, GOAL))
    assert elbow > 15.0 and "158 N m on joint 'elbow_joint'" in detail, detail
    assert "380 N m on joint 'shoulder_lift_joint'" in detail


@pytest.mark.parametrize("method", ["toppra", "jerk_limited"])
def test_other_methods_give_the_same_figures(client, method):
    timing = {"method": method, "limits": {"torque_scale": 0.2}}
    if method == "jerk_limited":
        timing["constraints"] = ["velocity", "acceleration", "torque", "jerk"]
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": W, "timing": timing})
    assert response.status_code == 422
    detail = response.json()["detail"]
    assert f"needs {abs(_gravity(GOAL)[1]):.4g} N m on joint 'shoulder_lift_joint'" in detail, detail
    assert "timing.limits.torque_scale 0.254" in detail


@pytest.mark.parametrize(
    ("robot", "path", "timing"),
    [
        ("ur5", W, {"method": "quintic", "limits": {"torque_scale": 0.2}}),
        ("ur5", W, {"method": "cubic", "duration": 6.0, "limits": {"torque_scale": 0.2}}),
        ("yamamoto_2r", {"waypoints": [[0.0, 0.0], [1.5, 0.0]]}, {"constraints": ["torque"], "limits": {"torque_scale": 0.1}}),
        ("yamamoto_2r", {"waypoints": [[0.0, 0.0], [1.5, 0.0]]}, {"method": "toppra", "constraints": ["torque"], "limits": {"torque_scale": 0.1}}),
        # Stopping at a corner: the first stretch fails, the remedy holds the second one too.
        ("ur5", {"interpolation": "linear", "waypoints": [START, [0.5, -1.1, 1.2, -0.2, 0.7, 0.1], GOAL]}, {"limits": {"torque_scale": 0.2}}),
    ],
    ids=["quintic", "cubic-with-duration", "yamamoto-phase-plane", "yamamoto-toppra", "corner"],
)
def test_every_refusal_that_holding_explains_gives_a_remedy_that_is_answered(client, robot, path, timing):
    body = {"robot": robot, "path": path, "timing": timing}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422
    detail = response.json()["detail"]
    assert "a lower limit scale" not in detail, detail
    scale = re.search(r"with timing\.limits\.torque_scale ([0-9.]+)", detail)
    assert scale is not None, detail
    followed = client.post("/v1/trajectories", json={**body, "timing": {**timing, "limits": {"torque_scale": float(scale.group(1))}}})
    assert followed.status_code == 200, followed.text


def test_a_load_no_accepted_limit_holds_is_told_so_without_advice_that_cannot_work(client):
    """1000 kg held 17 m from ur5's tool: holding it still needs about 1.1e5 N m on the wrist,
    beyond the largest torque limit a request may give (1e5 N m): no torque scale or limit is
    advised (one for the other joints alone would not plan the path), only a lighter payload."""
    waypoints = [[0, -1.2, 1, 0, 0.5, 0], [0.8, -1, 1.4, -0.5, 0.9, 0.3]]
    body = {"robot": "ur5", "path": {"waypoints": waypoints}, "payload": {"mass": 1000.0, "center_of_mass": [10.0, 10.0, 10.0]}}
    detail = client.post("/v1/trajectories", json=body).json()["detail"]
    assert "beyond any torque limit accepted (100000 N m): a lighter payload, or a path where the arm holds itself" in detail
    assert "every joint can hold the path still" not in detail and "timing.limits.torque" not in detail, detail


def test_limits_beyond_the_range_under_a_scale_are_advised_without_the_scale(client):
    """550 kg at 17 m from ur5's tool under torque_scale 0.5: the overrides that would hold it
    under the scale (up to 124,800 N m) lie beyond the accepted 100,000; the limits in force that
    hold it do not, and are advised without the scale: following that plans the path."""
    waypoints = [[0, -1.2, 1, 0, 0.5, 0], [0.8, -1, 1.4, -0.5, 0.9, 0.3]]
    payload = {"mass": 550.0, "center_of_mass": [10.0, 10.0, 10.0]}
    body = {"robot": "ur5", "path": {"waypoints": waypoints}, "payload": payload, "timing": {"limits": {"torque_scale": 0.5}}}
    detail = client.post("/v1/trajectories", json=body).json()["detail"]
    assert "(without timing.limits.torque_scale) (or more) every joint can hold the path still" in detail, detail
    advised = dict((joint, float(value)) for value, joint in re.findall(r"(\d+) N m on joint '(\w+)'", detail.split("; with ")[1]))
    assert max(advised.values()) <= 100_000
    names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    own = [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
    torque = [advised.get(name, limit) for name, limit in zip(names, own, strict=True)]
    followed = client.post("/v1/trajectories", json=body | {"timing": {"limits": {"torque": torque}}})
    assert followed.status_code == 200, followed.text[:300]
