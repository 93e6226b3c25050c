"""``path.continuous``: continuous joints follow the numbers given, with a warning when the
short way round is shorter, or turn the short way."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, WaypointPath, build_problem, plan
from toptraj.service.problems import note_text

TURN = np.array([[0.0, 0.2], [0.3, 6.0]])  # psi: 0.2 -> 6.0 rad, 5.8 rad as given, 0.483 the short way


def _planned(mode: str):
    return plan(build_problem(robots.load("geering_2r"), WaypointPath(TURN, continuous=mode), METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",))))


def test_as_given_follows_the_numbers_and_warns():
    result = _planned("as_given")
    np.testing.assert_allclose(result.samples.q[-1], TURN[-1], atol=1e-9)
    (note,) = [note for note in result.warnings if getattr(note, "rule", None) == "turns_the_long_way"]
    assert (note.facts["joint_name"], note.facts["field"]) == ("psi", "waypoints[0]")
    assert note.facts["turn"] == pytest.approx(5.8, abs=0.05)
    assert "'psi' turns +5.8 rad" in note_text(note) and "path.continuous = 'shortest'" in note_text(note)


def test_shortest_turns_the_short_way_to_the_equivalent_angle():
    given, short = _planned("as_given"), _planned("shortest")
    end = short.samples.q[-1]
    assert end[0] == pytest.approx(0.3, abs=1e-9)
    assert end[1] == pytest.approx(6.0 - 2 * np.pi, abs=1e-9)  # the same angle, whole turns apart
    assert np.ptp(short.samples.q[:, 1]) == pytest.approx(0.2 - (6.0 - 2 * np.pi), abs=1e-9)  # no detour
    # the same move done the short way, stated directly, takes the same time
    direct = plan(build_problem(robots.load("geering_2r"), WaypointPath(np.array([[0.0, 0.2], [0.3, 6.0 - 2 * np.pi]])), METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",))))
    assert short.duration == pytest.approx(direct.duration, rel=1e-12)
    assert short.duration < 0.5 * given.duration


def test_joints_with_limits_never_wrap(client):
    """ur5's joints have position limits (±2π): 'shortest' leaves them as given."""
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": [[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [5.0, -1.0, 1.4, 0.0, 0.5, 5.5]], "continuous": "shortest"},
        "timing": {"method": "phase_plane"},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    assert response.json()["samples"]["q"][-1][0] == pytest.approx(5.0, abs=1e-9)
    assert not any("continuous" in w for w in response.json()["warnings"])


def test_over_http_on_an_arm_with_three_continuous_joints(client):
    start = [0.1, 3.0, 1.5, 0.2, 1.5, 0.0]
    goal = [6.0, 3.1, 1.4, -6.0, 1.6, 3.5]  # joints 1, 4, 6 of the kinova are continuous
    body = {"robot": "kinova", "path": {"kind": "waypoints", "waypoints": [start, goal]}, "timing": {"method": "phase_plane"}}
    given = client.post("/v1/trajectories", json=body).json()
    assert sum("turns" in w and "more than pi" in w for w in given["warnings"]) == 3
    body["path"]["continuous"] = "shortest"
    short = client.post("/v1/trajectories", json=body).json()
    end = np.array(short["samples"]["q"][-1])
    np.testing.assert_allclose(np.cos(end), np.cos(goal), atol=1e-9)
    np.testing.assert_allclose(np.sin(end), np.sin(goal), atol=1e-9)
    assert np.all(np.abs(end - start) <= np.pi + 1e-9)
    assert short["duration"] < given["duration"]


def test_an_unknown_mode_is_a_422(client):
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": [[0.0] * 6, [0.1] * 6], "continuous": "longest"}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422 and "continuous" in response.text
