"""A blended path (straight segments and circular blends) has no finite jerk where a segment meets
a blend: the refusal's remedy depends on the method, and following it is served."""

from __future__ import annotations

import pytest

WAYPOINTS = [[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [0.8, -1.0, 1.4, -0.5, 0.9, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]]


def _body(timing: dict, interpolation: str = "blend") -> dict:
    return {"robot": "ur5", "path": {"interpolation": interpolation, "waypoints": WAYPOINTS}, "timing": timing}


@pytest.mark.parametrize(
    "timing, advice, followed",
    [
        # jerk_limited always limits jerk: leaving 'jerk' out of its constraints changes nothing
        ({"method": "jerk_limited", "constraints": ["velocity", "acceleration", "torque"]},
         "or time the blended path with a method without a jerk limit (phase_plane, toppra)",
         {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]}),
        # a time law limits jerk only when asked to
        ({"method": "quintic", "constraints": ["velocity", "acceleration", "torque", "jerk"]},
         "or leave 'jerk' out of timing.constraints",
         {"method": "quintic", "constraints": ["velocity", "acceleration", "torque"]}),
    ],
)
def test_a_blended_path_under_a_jerk_limit_names_a_remedy_that_serves(client, timing, advice, followed):
    refused = client.post("/v1/trajectories", json=_body(timing))
    assert refused.status_code == 422, refused.text
    detail = refused.json()["detail"]
    assert "jumps at s = " in detail and "use interpolation 'spline'" in detail and detail.endswith(advice)
    assert client.post("/v1/trajectories", json=_body(timing, "spline")).status_code == 200
    assert client.post("/v1/trajectories", json=_body(followed)).status_code == 200
