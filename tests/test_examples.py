"""Every request in examples/ is answered (the compare example by its own endpoint)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings

EXAMPLES = sorted((Path(__file__).parent.parent / "examples").glob("*.json"))


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    """The examples include a free-path collocation that takes tens of seconds on a loaded
    machine: a budget that lets it finish (the synchronous default is 20 s)."""
    settings = Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("data"), plan_budget_s=300.0)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


@pytest.mark.parametrize("example", EXAMPLES, ids=[path.stem for path in EXAMPLES])
def test_example_is_answered(client, example):
    body = json.loads(example.read_text())
    route = "/v1/trajectories/compare" if "methods" in body else "/v1/trajectories"
    response = client.post(route, json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    if "methods" in body:
        assert all(row.get("duration") for row in result["results"]), result
    else:
        assert result["duration"] > 0 and not [note for note in result["warnings"] if "limit" in note]
