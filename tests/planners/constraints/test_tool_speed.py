"""Tool-speed limits (``timing.limits.tool_speed``, ``tool_angular_speed``, ``tool_frame``): the
frame's speed recomputed from the returned samples by forward kinematics holds the limit and
reaches it, for every path kind and every method that takes constraints."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners.kinematics.ik import frame_pose
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.problem.waypoints import make_path

UR5_START = [0.3, -1.6, 1.7, -1.6, -1.57, 0.2]


def _poses(arm, frame: str, q: np.ndarray) -> list[pin.SE3]:
    model, data = arm.model, arm.data
    frame_id = arm.frame_id(frame)
    poses = []
    for configuration in arm.configuration(q):
        pin.forwardKinematics(model, data, configuration)
        poses.append(pin.updateFramePlacement(model, data, frame_id).copy())
    return poses


def tool_speeds_from_samples(arm, frame: str, body: dict) -> tuple[np.ndarray, np.ndarray]:
    """Linear (m/s) and angular (rad/s) speed of ``frame`` between consecutive samples, from
    their forward kinematics by finite differences (midpoint values)."""
    t = np.array(body["samples"]["t"])
    poses = _poses(arm, frame, np.array(body["samples"]["q"]))
    dt = np.diff(t)
    linear = np.array([np.linalg.norm(b.translation - a.translation) for a, b in zip(poses[:-1], poses[1:])]) / dt
    angular = np.array([np.linalg.norm(pin.log3(b.rotation @ a.rotation.T)) for a, b in zip(poses[:-1], poses[1:])]) / dt
    return linear, angular


def _ur5_line_end(arm) -> tuple[np.ndarray, float]:
    start = np.array(UR5_START)
    p0 = frame_pose(arm, start, arm.frame_id("tool0")).translation
    p1 = p0 + np.array([0.0, 0.3, -0.1])
    return p1, float(np.linalg.norm(p1 - p0))


def _ramp_time(arm, path, s: float, speed: float, acceleration: np.ndarray) -> float:
    """Time lost in reaching (or leaving) the cruise speed at the end s of a straight tool line,
    from the joint acceleration limits there: the path acceleration available at rest is
    u = min_j a_j / |q'_j|, the tool accelerates at |J_v q'| u, and a constant acceleration a
    to the speed v costs v / (2 a) over cruising the same distance."""
    points = path.evaluate(np.array([s]), "left" if s == 1.0 else "right")
    model, data = arm.model, arm.data
    pin.forwardKinematics(model, data, arm.configuration(points.q)[0], points.dq[0])
    tool_per_sd = np.linalg.norm(pin.getFrameVelocity(model, data, arm.frame_id("tool0"), pin.LOCAL_WORLD_ALIGNED).linear)
    with np.errstate(divide="ignore"):
        u = np.min(acceleration / np.abs(points.dq[0]))
    return speed / (2.0 * tool_per_sd * u)


@pytest.mark.parametrize("method", ["phase_plane", "toppra", "min_cost"])
def test_a_cartesian_line_cruises_at_the_tool_speed(client, method):
    """A straight line of ur5's tool at 5 cm/s, joint accelerations scaled so that speeding up
    and slowing down take a visible part of the motion: the tool speed from the samples' forward
    kinematics stays within 0.5 % of the limit and reaches it, and the duration is the line's
    length over the speed plus the two acceleration phases (from the joint limits at the ends)
    within 1 %."""
    arm = robots.load("ur5")
    p1, length = _ur5_line_end(arm)
    speed, scale = 0.05, 0.01
    body = {
        "robot": "ur5",
        "path": {"kind": "cartesian", "start": UR5_START, "positions": [p1.tolist()]},
        "timing": {
            "method": method,
            "constraints": ["velocity", "acceleration"],
            "limits": {"tool_speed": speed, "acceleration_scale": scale},
        },
        "output": {"dt": 0.002},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    linear, _ = tool_speeds_from_samples(arm, "tool0", result)
    assert linear.max() <= 1.005 * speed
    assert linear.max() >= 0.995 * speed
    assert result["peak_utilization"]["tool_speed"] == pytest.approx(1.0, abs=0.005)

    path = make_path(arm, CartesianLine(start=np.array(UR5_START), positions=np.array([p1])))
    acceleration = arm.limits.acceleration * scale
    ramps = _ramp_time(arm, path, 0.0, speed, acceleration) + _ramp_time(arm, path, 1.0, speed, acceleration)
    assert ramps > 0.1 * length / speed  # the acceleration phases matter
    assert result["duration"] == pytest.approx(length / speed + ramps, rel=0.01)
    # Between the acceleration phases the tool cruises at the limit.
    t = np.array(result["samples"]["t"])[1:]
    cruise = (t > 2.5 * ramps) & (t < result["duration"] - 2.5 * ramps)
    assert np.abs(linear[cruise] / speed - 1.0).max() < 0.005


def test_a_waypoint_path_holds_an_angular_tool_speed(client):
    arm = robots.load("ur5")
    limit = 0.4
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
        "timing": {"method": "phase_plane", "limits": {"tool_angular_speed": limit}},
        "output": {"dt": 0.002},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    _, angular = tool_speeds_from_samples(arm, "tool0", result)
    assert angular.max() <= 1.005 * limit
    assert angular.max() >= 0.99 * limit
    assert result["peak_utilization"]["tool_angular_speed"] == pytest.approx(1.0, abs=0.005)
    assert "tool_speed" not in result["peak_utilization"] or result["peak_utilization"]["tool_speed"] is None
    free = client.post("/v1/trajectories", json={**body, "timing": {"method": "phase_plane"}}).json()
    assert free["duration"] < 0.9 * result["duration"]


@pytest.mark.parametrize("method", ["phase_plane", "toppra", "min_cost", "cubic", "quintic", "trapezoidal", "cycloidal"])
def test_every_method_holds_the_tool_speed_on_a_stop_and_go_path(client, method):
    """Straight joint segments that stop at each waypoint, each stretch timed on its own."""
    arm = robots.load("ur5")
    limit = 0.25
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:3], "interpolation": "linear"},
        "timing": {"method": method, "limits": {"tool_speed": limit}},
        "output": {"dt": 0.002},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    linear, _ = tool_speeds_from_samples(arm, "tool0", result)
    assert linear.max() <= 1.005 * limit
    assert result["peak_utilization"]["tool_speed"] <= 1.003
    if method in ("phase_plane", "toppra", "min_cost"):
        assert linear.max() >= 0.99 * limit
    else:
        # A time law's shortest duration is set by its binding limit: here the tool's speed.
        assert result["binding"]["kind"] == "tool_speed"
        assert result["peak_utilization"]["tool_speed"] == pytest.approx(1.0, abs=0.003)


def test_a_named_frame_and_the_margin(client):
    """The limit applies to the frame named; timing.limit_margin keeps its share in reserve."""
    arm = robots.load("ur5")
    limit, margin = 0.2, 0.1
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
        "timing": {"limits": {"tool_speed": limit, "tool_frame": "forearm_link"}, "limit_margin": margin},
        "output": {"dt": 0.002},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    linear, _ = tool_speeds_from_samples(arm, "forearm_link", result)
    assert linear.max() <= limit * (1 - margin) * 1.003
    assert linear.max() >= limit * (1 - margin) * 0.99
    assert result["peak_utilization"]["tool_speed"] == pytest.approx(1 - margin, abs=0.005)
    tool0, _ = tool_speeds_from_samples(arm, "tool0", result)
    assert tool0.max() > 1.2 * limit  # the end effector itself is not limited


@pytest.mark.parametrize(
    "timing, path, words",
    [
        ({"limits": {"tool_speed": 0.1, "tool_frame": "gripper"}}, None, ["tool_frame", "'gripper'", "'tool0'", "'wrist_3_link'"]),
        ({"limits": {"tool_frame": "tool0"}}, None, ["tool_speed"]),
        ({"limits": {"tool_speed": 0.0}}, None, ["tool_speed"]),
        ({"method": "cubic", "limits": {"tool_speed": 0.1}}, "via", ["via"]),
    ],
)
def test_bad_tool_limits_are_422(client, timing, path, words):
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, **({"interpolation": path} if path else {})},
        "timing": timing,
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    text = response.text
    for word in words:
        assert word in text


def test_a_free_path_refuses_a_tool_limit(client):
    body = {
        "robot": "geering_2r",
        "path": {"kind": "free", "start": [0.0, 0.0], "goal": [1.0, -1.0]},
        "timing": {"method": "collocation", "limits": {"tool_speed": 0.1}},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert "collocation" in response.json()["detail"]


@pytest.mark.parametrize("limits, named", [({"tool_speed": 1e-6}, "raise timing.limits.tool_speed or the velocity"),
                                           ({"velocity": [1e-6] * 6}, "raise the velocity and acceleration limits")])
def test_a_motion_too_slow_for_any_dt_gets_advice_it_can_follow(client, limits, named):
    """No output.dt within its range (at most 10 s) serves a motion of days: the answer says
    which limits to raise instead of advising an output.dt beyond its own range."""
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:2]},
        "timing": {"method": "phase_plane", "limits": limits},
        "output": {"dt": 0.01},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert "even the largest output.dt (10 s) serves at most" in detail and named in detail
    assert all(float(value) <= 10.0 for value in re.findall(r"output\.dt >= ([0-9.e+-]+)", detail))
    fitting = {**body, "output": {"dt": 10.0}}
    assert client.post("/v1/trajectories", json=fitting).status_code == 422  # advice was right: no dt serves
