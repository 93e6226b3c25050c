"""The body of a trajectory is capped (422 naming the smallest ``output.dt`` that fits), built
and encoded off the event loop, and ``/health`` answers while a large body is produced."""

from __future__ import annotations

import asyncio
import json
import re
import threading

import httpx
import pytest
from fastapi.testclient import TestClient

from tests.conftest import UR5_WAYPOINTS
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

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


def _health_while_rendering(monkeypatch, body: dict):
    """Post ``body`` to an app in this process whose ``render`` (which builds and encodes the
    answer's body) first waits until a ``/health`` sent once it started is answered: the
    answer, and whether ``render`` ran at all. Were the body built on the event loop, the
    loop could not answer ``/health`` and the wait would end in its hang guard (a 500)."""
    import toptraj.service.planning
    import toptraj.service.routes.trajectories as routes

    rendering, health_answered = threading.Event(), threading.Event()
    original = toptraj.service.planning.render

    def watched(*args, **kwargs):
        rendering.set()
        assert health_answered.wait(60.0), "/health was not answered while the body was produced"
        return original(*args, **kwargs)

    monkeypatch.setattr(routes, "render", watched)
    app = create_app(Settings(preload_robots=False, plan_budget_s=120.0))

    async def scenario():
        async with httpx.AsyncClient(transport=httpx.ASGITransport(app=app), base_url="http://toptraj", timeout=180.0) as client:
            posted = asyncio.create_task(client.post("/v1/trajectories", json=body))
            while not rendering.is_set() and not posted.done():
                await asyncio.sleep(0.001)
            if rendering.is_set():
                assert (await client.get("/health")).status_code == 200
                health_answered.set()
            return await posted

    try:
        return asyncio.run(scenario()), rendering.is_set()
    finally:
        app.state.planning.close()


def test_health_answers_while_a_large_body_is_produced(monkeypatch):
    """A 1 kB request asking for samples every 10 microseconds used to build a 75 MB body on the
    event loop, and /health waited seconds behind it: it is refused before any body is built,
    and the largest body allowed (over 10 MB) is built while /health is answered (an order
    of events, whatever the machine's load)."""
    refused, rendered = _health_while_rendering(monkeypatch, {**REQUEST, "output": {"dt": 1e-5}})
    assert refused.status_code == 422, refused.text[:300]
    assert not rendered
    largest = {**REQUEST, "output": {"dt": _smallest_dt(refused.json()["detail"])}}
    response, rendered = _health_while_rendering(monkeypatch, largest)
    assert response.status_code == 200, response.text[:300]
    assert rendered
    assert 10_000_000 < len(response.content) <= Settings().max_response_bytes
