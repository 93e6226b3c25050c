"""An ``output.dt`` too long for the motion is warned of: a period longer than the motion (its
samples cannot follow it) and a motion slowed by more than 1 % to end on a whole period
(``output.exact_period``), with the figures the samples show."""

from __future__ import annotations

import math

import numpy as np

from tests.conftest import UR5_WAYPOINTS

PATH = {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": "spline"}


def _answer(client, **output):
    body = {"robot": "ur5", "path": PATH, "timing": {"method": "phase_plane"}, "output": output}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    return response.json()


def _about(warnings: list[str], words: str) -> list[str]:
    return [warning for warning in warnings if words in warning]


def test_a_period_longer_than_the_motion_is_warned_of(client):
    answer = _answer(client, dt=10)  # a user meaning milliseconds
    duration = answer["duration"]
    assert len(answer["samples"]["t"]) == 2
    (warning,) = _about(answer["warnings"], "output.dt = 10 s")
    assert "2 samples" in warning and "in seconds" in warning
    assert f"output.dt <= {duration / 100:.3g} s" in warning
    assert not _about(answer["warnings"], "slows the motion")  # the samples format keeps the planned timing


def test_a_motion_slowed_to_whole_periods_says_by_how_much(client):
    answer = _answer(client, dt=1, format="joint_trajectory")
    duration = answer["duration"]
    scale = math.ceil(duration) / duration  # whole periods of 1 s
    (warning,) = _about(answer["warnings"], "slows the motion")
    assert f"by {100 * (scale - 1):.3g} %" in warning and f"last {math.ceil(duration):g} s" in warning
    assert "peak_utilization is that of the planned timing" in warning
    assert f"velocities {1 / scale:.3g}, accelerations {scale**-2:.3g}" in warning
    # the samples delivered are the planned motion at t / k, its velocities divided by k
    planned = _answer(client, dt=0.001)
    points = answer["joint_trajectory"]["points"]
    t = np.array([point["time_from_start"]["sec"] + 1e-9 * point["time_from_start"]["nanosec"] for point in points])
    delivered = np.array([point["velocities"] for point in points])
    planned_t, planned_qd = np.array(planned["samples"]["t"]), np.array(planned["samples"]["qd"])
    expected = np.column_stack([np.interp(t / scale, planned_t, planned_qd[:, j]) for j in range(planned_qd.shape[1])]) / scale
    np.testing.assert_allclose(delivered, expected, rtol=0, atol=1e-4 * np.abs(planned_qd).max())

def test_a_slowing_within_one_percent_is_not_warned_of(client):
    answer = _answer(client, dt=0.01, format="joint_trajectory")
    assert answer["sampled_duration"] / answer["duration"] - 1 < 0.01
    assert not _about(answer["warnings"], "slows the motion") and not _about(answer["warnings"], "output.dt =")


def test_a_comparison_which_returns_no_samples_warns_of_none(client):
    """A comparison samples coarsely for its figures and returns no samples, and its body takes
    no ``output``: a sampling warning would advise what it cannot take."""
    short = {"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]]}
    body = {"robot": "ur5", "path": short, "methods": ["phase_plane", "toppra"]}
    response = client.post("/v1/trajectories/compare", json=body)
    assert response.status_code == 200, response.text
    for entry in response.json()["results"]:
        assert entry["duration"] < 1.0  # shorter than the comparison's own period
        assert not _about(entry["warnings"], "output.dt") and not _about(entry["warnings"], "slows the motion"), entry
