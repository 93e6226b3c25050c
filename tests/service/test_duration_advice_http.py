"""A ``timing.duration`` too short for its law under the limits: the 422 names the shortest
duration that holds them, and that advice, followed, is answered."""

from __future__ import annotations

import re

import pytest

W = {"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]]}
VIA = {"kind": "waypoints", "interpolation": "via", "waypoints": [*W["waypoints"], [1.5, -0.5, 0.8, -1, 1, 0.8]]}


def test_the_quintic_too_short_is_told_its_shortest_duration(client):
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": W, "timing": {"method": "quintic", "duration": 0.1}})
    assert response.status_code == 422
    detail = response.json()["detail"]
    # 0.76 s: sqrt(10 / sqrt(3) * 1 rad / 10 rad/s^2) = 0.7598 s rounded up (tests/planners/runner/test_duration_too_short.py).
    assert detail.startswith(
        "timing.duration 0.1 s is too short for the quintic law under these limits: the shortest is 0.76 s; give at least "
        "that or leave timing.duration out"
    ), detail
    assert "a lower limit scale or more grid points" not in detail


@pytest.mark.parametrize(
    ("path", "timing"),
    [
        (W, {"method": "quintic", "duration": 0.1}),
        (W, {"method": "cubic", "duration": 0.5}),
        (W, {"method": "trapezoidal", "duration": 0.5}),
        (W, {"method": "cycloidal", "duration": 0.3, "limit_margin": 0.2}),
        (W, {"method": "quintic", "duration": 0.3, "supporting_points": 5}),
        (W, {"method": "quintic", "duration": 0.3, "synchronization": "none"}),
        (VIA, {"method": "quintic", "duration": 0.3}),
    ],
    ids=["quintic", "cubic", "trapezoidal", "cycloidal-margin", "spline-law", "unsynchronized", "via-points"],
)
def test_the_duration_advised_is_answered(client, path, timing):
    body = {"robot": "ur5", "path": path, "timing": timing}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422
    detail = response.json()["detail"]
    advised = re.search(r"(?:the shortest is|a duration of) ([0-9.]+) s(?: holds them)?; give at least that", detail)
    assert advised is not None, detail
    seconds = float(advised.group(1))
    followed = client.post("/v1/trajectories", json={**body, "timing": {**timing, "duration": seconds}})
    assert followed.status_code == 200, followed.text
    assert followed.json()["duration"] == pytest.approx(seconds, rel=1e-9)
    assert client.post("/v1/trajectories", json={**body, "timing": {**timing, "duration": 1.5 * seconds}}).status_code == 200


@pytest.mark.parametrize("law", ["cubic", "quintic"])
def test_a_via_point_motion_given_any_duration_above_its_shortest_is_answered(client, law):
    """A given duration runs the shortest motion more slowly as a whole: 1.25 s, above the
    shortest 1.2488 s, broke the acceleration limit by 3 % (the duration was shared among the
    segments otherwise than the shortest shares it) with advice no grid could follow."""
    path = {**VIA, "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [0.8, -1, 1.4, -0.5, 0.9, 0.3], [2, -1.3, 1.2, 0.2, 0.6, 1.2]]}
    body = {"robot": "ur5", "path": path, "timing": {"method": law}, "output": {"dt": 0.01}}
    shortest = client.post("/v1/trajectories", json=body).json()
    for factor in (1.0005, 1.01, 1.5):
        given = round(factor * shortest["duration"], 4)
        answered = client.post("/v1/trajectories", json={**body, "timing": {"method": law, "duration": given}})
        assert answered.status_code == 200, (factor, answered.text)
        assert answered.json()["duration"] == given
        peaks = answered.json()["peak_utilization"]
        assert max(max(peaks["velocity"]), max(peaks["acceleration"])) <= 1.0 / factor**1 + 1e-9


def test_a_duration_too_short_joint_by_joint_names_the_slowest_joint(client):
    """Joint by joint, a duration shorter than the slowest joint's own speeds every joint up by
    the same factor, and every joint exceeds its limit by the same share: the refusal named the
    first joint (shoulder_pan_joint); it names the joint whose own duration is the motion's,
    the one the answer without a duration reports as binding, and the excess the factor gives."""
    path = {"waypoints": [[0, 0, 0, 0, 0, 0], [0.2, 1.5, 0.3, 0.1, 0.1, 0.1]], "interpolation": "linear"}
    timing = {"method": "trapezoidal", "synchronization": "none", "constraints": ["velocity", "acceleration"]}
    shortest = client.post("/v1/trajectories", json={"robot": "ur5", "path": path, "timing": timing}).json()
    assert shortest["binding"]["joint"] == "shoulder_lift_joint"
    refused = client.post("/v1/trajectories", json={"robot": "ur5", "path": path, "timing": {**timing, "duration": 0.5}})
    detail = refused.json()["detail"]
    excess = 100 * ((shortest["duration"] / 0.5) ** 2 - 1)  # accelerations scale with 1 / T^2
    assert f"the acceleration limit of joint 'shoulder_lift_joint' is exceeded by {excess:.2f} %" in detail


def test_a_duration_too_short_joint_by_joint_names_the_limit_most_exceeded(client):
    """Shortened by a factor f, a joint whose own duration a velocity limit sets is over it by
    1/f, one that an acceleration limit sets by 1/f^2: geering_2r's first joint is velocity-bound
    (and the slowest), its second acceleration-bound; at 0.8 of the shortest duration the second
    is over by 56.25 %, the first by 25 %, and the second is named."""
    timing = {"method": "trapezoidal", "synchronization": "none", "constraints": ["velocity", "acceleration"],
              "limits": {"velocity": [1, 1], "acceleration": [10, 0.1]}}
    body = {"robot": "geering_2r", "path": {"waypoints": [[0, 0], [2.7, 0.35]], "interpolation": "linear"}, "timing": timing}
    shortest = client.post("/v1/trajectories", json=body).json()
    assert shortest["binding"] == {"kind": "velocity", "joint": "phi", "s": pytest.approx(1 / 3)}
    refused = client.post("/v1/trajectories", json={**body, "timing": {**timing, "duration": 0.8 * shortest["duration"]}})
    assert "the acceleration limit of joint 'psi' is exceeded by 56.25 %" in refused.json()["detail"]
