"""The body of a trajectory is capped (422 naming the smallest ``output.dt`` that fits), built
and encoded off the event loop, and ``/health`` answers while a large body is produced."""

from __future__ import annotations

import json
import re
import threading
import time

import pytest
from fastapi.testclient import TestClient

from service.app import create_app
from service.settings import Settings
from tests.conftest import UR5_WAYPOINTS
from tests.live_server import LiveServer

CAP = 1_000_000
REQUEST = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "timing": {"method": "phase_plane"}}


def _smallest_dt(detail: str) -> float:
    return float(re.search(r"use output\.dt >= ([0-9.e+-]+) s", detail).group(1))


@pytest.fixture(scope="module")
def capped():
    with TestClient(create_app(Settings(preload_robots=False, max_response_bytes=CAP))) as client:
        yield client


def test_a_body_over_the_cap_is_refused_with_the_smallest_dt_that_fits(capped):
    response = capped.post("/v1/trajectories", json={**REQUEST, "output": {"dt": 1e-5}})
    assert response.status_code == 422, response.text[:300]
    assert response.headers["content-type"] == "application/problem+json"
    detail = response.json()["detail"]
    assert "output.dt = 1e-05 s" in detail and len(response.content) < 2_000
    dt = _smallest_dt(detail)
    fits = capped.post("/v1/trajectories", json={**REQUEST, "output": {"dt": dt}})
    assert fits.status_code == 200, fits.text[:300]
    assert len(fits.content) <= CAP
    samples = fits.json()["samples"]
    assert len(samples["t"]) == len(samples["tau"]) > 1000  # the cap is used, not wasted
    assert samples["t"][1] == pytest.approx(dt)
    too_fine = capped.post("/v1/trajectories", json={**REQUEST, "output": {"dt": dt * 0.98}})
    assert too_fine.status_code == 422
    assert _smallest_dt(too_fine.json()["detail"]) == dt


def test_the_body_is_plain_json_with_the_same_numbers(capped):
    response = capped.post("/v1/trajectories", json={**REQUEST, "output": {"dt": 0.01}})
    assert response.status_code == 200 and response.headers["content-type"] == "application/json"
    body = json.loads(response.content)
    assert body["duration"] == body["samples"]["t"][-1]
    assert all(len(row) == 6 for row in body["samples"]["q"])


def _health_during(server: LiveServer, body: dict):
    """Send ``body`` in a thread and poll ``/health`` until it is answered: the answer and the
    slowest ``/health`` round trip."""
    answer = {}
    thread = threading.Thread(target=lambda: answer.update(response=server.request("POST", "/v1/trajectories", body)))
    thread.start()
    slowest = 0.0
    while True:
        start = time.monotonic()
        assert server.request("GET", "/health", timeout=60)[0] == 200
        slowest = max(slowest, time.monotonic() - start)
        if not thread.is_alive():
            break
        time.sleep(0.05)
    thread.join()
    return answer["response"], slowest


def test_health_answers_while_a_large_body_is_produced():
    """A 1 kB request asking for samples every 10 microseconds used to build a 75 MB body on the
    event loop, and /health waited seconds behind it. (The bound of 2 s is a hang check.)"""
    with LiveServer(TOPTRAJ_PRELOAD_ROBOTS="false") as server:
        assert server.request("GET", "/v1/robots/ur5")[0] == 200
        (status, _, content), slowest = _health_during(server, {**REQUEST, "output": {"dt": 1e-5}})
        assert slowest < 2.0
        assert status == 422, content[:300]
        largest = {**REQUEST, "output": {"dt": _smallest_dt(json.loads(content)["detail"])}}
        (status, _, content), slowest = _health_during(server, largest)
        assert slowest < 2.0
        assert status == 200, content[:300]
        assert 10_000_000 < len(content) <= Settings().max_response_bytes
