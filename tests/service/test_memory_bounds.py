"""Memory per request and in total is bounded: each method's grid is capped by its measured
memory (422 suggesting a value), and at most ``plan_workers`` plannings run at once, with
``plan_queue`` more waiting; beyond that a request gets 503 with ``Retry-After``."""

from __future__ import annotations

import asyncio

import httpx
import pytest
from fastapi.testclient import TestClient

from tests.conftest import UR5_WAYPOINTS
from tests.planners.execution.test_budget_stops_work import SLOW
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

YAMAMOTO_LINE = [[0.0, 0.0], [0.5, 0.3]]


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=5.0))) as test_client:
        yield test_client


@pytest.mark.parametrize(
    "robot, waypoints, method, grid_points, largest",
    [
        ("ur5", UR5_WAYPOINTS, "min_cost", 5000, 4000),  # 6 joints
        ("yamamoto_2r", YAMAMOTO_LINE, "min_cost", 12_001, 12_000),  # 2 joints
    ],
)
def test_a_grid_over_the_method_memory_cap_gets_422_with_a_value(client, robot, waypoints, method, grid_points, largest):
    body = {"robot": robot, "path": {"waypoints": waypoints}, "timing": {"method": method, "grid_points": grid_points}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text[:300]
    detail = response.json()["detail"]
    assert f"timing.grid_points = {grid_points}" in detail and f"use timing.grid_points <= {largest}" in detail


def test_min_cost_at_its_largest_grid_on_a_small_arm_is_served(patient_client):
    """The largest grid the cap allows a 2-joint arm (12,000 points, one fewer than the refused
    12,001 above) is planned, within its memory estimate, and served (a budget that a loaded
    machine does not spend: the solve takes about 5 s on 2 busy cores)."""
    body = {"robot": "yamamoto_2r", "path": {"waypoints": YAMAMOTO_LINE}, "timing": {"method": "min_cost", "grid_points": 12_000}}
    response = patient_client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text[:300]
    assert response.json()["method"] == "min_cost"


FAST = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS[:2]}, "timing": {"method": "phase_plane"}}


def test_requests_beyond_the_queue_get_503_with_retry_after():
    """One worker, no queue: while a slow planning runs, the next request is refused at once,
    /health still answers, and a retry after Retry-After gets through once the worker is free."""
    app = create_app(Settings(preload_robots=False, plan_workers=1, plan_queue=0, plan_budget_s=1.0))

    async def scenario():
        async with httpx.AsyncClient(transport=httpx.ASGITransport(app=app), base_url="http://toptraj") as client:
            slow = asyncio.create_task(client.post("/v1/trajectories", json=SLOW["via_points"]))
            while app.state.planning._admitted == 0:  # the slow planning holds the worker
                await asyncio.sleep(0.001)
            busy = await client.post("/v1/trajectories", json=FAST)
            health = await client.get("/health")
            first = await slow
            for _ in range(100):
                retry = await client.post("/v1/trajectories", json=FAST)
                if retry.status_code != 503:
                    break
                await asyncio.sleep(0.05 * int(retry.headers["retry-after"]))
            return busy, health, first, retry

    busy, health, first, retry = asyncio.run(scenario())
    assert busy.status_code == 503, busy.text[:300]
    assert busy.headers["content-type"] == "application/problem+json"
    assert int(busy.headers["retry-after"]) >= 1
    assert "busy" in busy.json()["detail"]
    assert health.status_code == 200
    assert first.status_code == 504
    assert retry.status_code == 200


def test_a_request_waits_for_a_worker_within_its_budget():
    """With a queue, the second request waits for the worker instead of being refused."""
    app = create_app(Settings(preload_robots=False, plan_workers=1, plan_queue=1, plan_budget_s=10.0))
    short = {**FAST, "timing": {"method": "cubic"}}

    async def scenario():
        async with httpx.AsyncClient(transport=httpx.ASGITransport(app=app), base_url="http://toptraj") as client:
            return await asyncio.gather(*(client.post("/v1/trajectories", json=short) for _ in range(2)))

    assert [response.status_code for response in asyncio.run(scenario())] == [200, 200]


def test_an_app_started_again_keeps_planning_and_loses_no_worker():
    """Test clients start and stop an app's lifespan around each use, sometimes overlapping (a
    fuzzer beside a module client). Every request after a stop is planned, and the one worker
    is never lost, however many starts and stops came before."""
    app = create_app(Settings(preload_robots=False, plan_workers=1, plan_queue=0, plan_budget_s=10.0))
    short = {**FAST, "timing": {"method": "cubic"}}
    with TestClient(app) as outer:
        for _ in range(3):
            with TestClient(app) as inner:
                assert inner.post("/v1/trajectories", json=short).status_code == 200
            assert outer.post("/v1/trajectories", json=short).status_code == 200
    after_stop = TestClient(app)  # no lifespan at all
    assert [after_stop.post("/v1/trajectories", json=short).status_code for _ in range(3)] == [200] * 3
