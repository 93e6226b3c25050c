"""Memory per request and in total is bounded: each method's grid is admitted by its measured
memory against one cap (422 naming the largest grid that fits), and at most ``plan_workers`` plannings run at once, with
``plan_queue`` more waiting; beyond that a request gets 503 with ``Retry-After``."""

from __future__ import annotations

import asyncio
import re

import httpx
import pytest
from fastapi.testclient import TestClient

from tests.conftest import UR5_WAYPOINTS
from tests.planners.execution.test_budget_stops_work import SLOW
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.service.app import create_app
from toptraj.service.planning import samples_within
from toptraj.service.settings import Settings

YAMAMOTO_LINE = [[0.0, 0.0], [0.5, 0.3]]


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=5.0))) as test_client:
        yield test_client


ADVICE = re.compile(r"use timing\.grid_points <= (\d+)")


def _min_cost(robot, waypoints, grid_points):
    return {"robot": robot, "path": {"waypoints": waypoints}, "timing": {"method": "min_cost", "grid_points": grid_points}}


@pytest.mark.parametrize("robot, waypoints, dof", [("ur5", UR5_WAYPOINTS, 6), ("yamamoto_2r", YAMAMOTO_LINE, 2)])
def test_a_grid_over_the_memory_cap_gets_422_naming_the_largest_that_fits(client, robot, waypoints, dof):
    """The grid field's own largest value (20,000 intervals) is over min_cost's memory on both
    arms: the 422 names the largest grid that fits, which one more interval exceeds. The rule's
    figures written out: 9,000 bytes per interval and joint, a cap of 140,000 x 2,300 bytes,
    less the samples the answer may hold (those the response cap allows), 5 x 8 bytes per
    sample and joint."""
    response = client.post("/v1/trajectories", json=_min_cost(robot, waypoints, MAX_POINTS))
    assert response.status_code == 422, response.text[:300]
    largest = int(ADVICE.search(response.json()["detail"]).group(1))
    samples = min(200_000, samples_within(Settings().max_response_bytes, dof))
    assert largest == (140_000 * 2_300 - samples * dof * 5 * 8) // (9_000 * dof)
    beyond = client.post("/v1/trajectories", json=_min_cost(robot, waypoints, largest + 1))
    assert beyond.status_code == 422 and f"<= {largest}" in beyond.json()["detail"], beyond.text[:300]


def test_min_cost_at_its_largest_grid_on_a_small_arm_is_served(client, patient_client):
    """The largest grid the 422 advises for a 2-joint arm (the real largest, about 17,000
    intervals) is planned and served (a budget that a loaded machine does not spend)."""
    refused = client.post("/v1/trajectories", json=_min_cost("yamamoto_2r", YAMAMOTO_LINE, MAX_POINTS))
    largest = int(ADVICE.search(refused.json()["detail"]).group(1))
    response = patient_client.post("/v1/trajectories", json=_min_cost("yamamoto_2r", YAMAMOTO_LINE, largest))
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


def test_a_period_giving_exactly_the_most_samples_served_is_served(tmp_path):
    """The refusal counts the samples as the sampling makes them (every dt from 0, and the
    final instant: ceil(T / dt) + 1); a period whose count is the most served was refused while
    the message said it gave that many ("gives 1952 samples ... at most 1952 are served")."""
    from fastapi.testclient import TestClient

    settings = Settings(preload_robots=False, data_dir=tmp_path, max_response_bytes=1_000_000)
    body = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "output": {"dt": 0.00001}}
    with TestClient(create_app(settings)) as client:
        refused = client.post("/v1/trajectories", json=body)
        assert refused.status_code == 422, refused.text[:300]
        most = int(re.search(r"at most (\d+) are served", refused.json()["detail"]).group(1))
        duration = client.post("/v1/trajectories", json={**body, "output": {"dt": 0.01}}).json()["duration"]
        dt = duration / (most - 1.5)  # ceil(T / dt) + 1 = most
        served = client.post("/v1/trajectories", json={**body, "output": {"dt": dt}})
        assert served.status_code == 200, served.text[:300]
        assert len(served.json()["samples"]["t"]) == most
