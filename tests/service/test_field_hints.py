"""A field put in the wrong place: the 422 says where a field of that name belongs in the body's
schema (``toptraj.service.field_hints``), and nothing for a name the schema does not have."""

from __future__ import annotations

import pytest

from toptraj.service.field_hints import field_places

WAYPOINTS = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 6]}}


@pytest.mark.parametrize(
    ("body", "detail"),
    [
        ({**WAYPOINTS, "format": "csv"}, "format: Extra inputs are not permitted: 'format' belongs in output.format"),
        ({**WAYPOINTS, "timing": {"dt": 0.01}}, "timing.dt: Extra inputs are not permitted: 'dt' belongs in output.dt"),
        ({**WAYPOINTS, "timing": {"bogus": 1}}, "timing.bogus: Extra inputs are not permitted"),
    ],
    ids=["top-level format", "dt under timing", "unknown name"],
)
def test_a_misplaced_field_is_refused_with_where_it_belongs(client, body, detail):
    answer = client.post("/v1/trajectories", json=body)
    assert answer.status_code == 422
    assert answer.json()["detail"] == detail


def test_the_advised_place_is_accepted(client):
    """Moving the field where the hint says gives a 200."""
    answer = client.post("/v1/trajectories", json={**WAYPOINTS, "output": {"format": "csv"}})
    assert answer.status_code == 200


def test_places_inside_lists_are_written_with_an_index():
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    places = field_places(TrajectoryRequest)
    assert "timing.zones[i].tool_speed" in places["tool_speed"]
    assert places["format"] == ("output.format",)
