"""Every request in examples/ is answered (the compare example by its own endpoint)."""

from __future__ import annotations

import json

import pytest

from tests.paths import ROOT

EXAMPLES = sorted((ROOT / "examples").glob("*.json"))


@pytest.fixture(scope="module")
def client(patient_client):
    """The examples include a free-path collocation."""
    return patient_client


@pytest.mark.parametrize("example", EXAMPLES, ids=[path.stem for path in EXAMPLES])
def test_example_is_answered(client, example):
    body = json.loads(example.read_text())
    if "arms" in body:
        _cell_example_is_answered(client, body)
        return
    route = "/v1/trajectories/compare" if "methods" in body else "/v1/trajectories"
    response = client.post(route, json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    if "methods" in body:
        assert all(row.get("duration") for row in result["results"]), result
    else:
        assert result["duration"] > 0 and not [note for note in result["warnings"] if "limit" in note]
    if body["path"].get("obstacles"):
        assert result["min_clearance"]["distance"] >= body["path"]["clearance"]


def _cell_example_is_answered(client, body):
    response = client.post("/v1/cells", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    assert result["duration"] >= max(result["solo_durations"]) > 0
    assert result["min_distance"]["guaranteed"] >= body["clearance"]
