"""Heavy plannings (``toptraj.service.planning.heavy``) are admitted apart from the short ones: while
searches run over their budget, the typical request keeps its latency, and once they end the
server is idle again and holds the memory it held before."""

from __future__ import annotations

import asyncio
import json
import threading
import time

import httpx
import psutil
import pytest

from tests.live_server import LiveServer
from tests.planners.generators.test_search_budget import UR5_BOX, UR5_GOAL, UR5_START
from toptraj.service.app import create_app
from toptraj.service.planning import heavy, heavy_request
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest
from toptraj.service.settings import Settings

#: The typical request (``benchmarks/end_to_end.py``): ur5, 4 spline waypoints, phase_plane.
TYPICAL = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": [
        [0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
        [1.5, -0.5, 0.8, -1.0, 1.0, 0.8], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
    ]},
    "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
}
#: The default ur5 search around one box (about 390 bytes): about 3.3 s of work on its own.
SEARCH = {
    "robot": "ur5",
    "path": {"kind": "free", "start": UR5_START, "goal": UR5_GOAL, "obstacles": [UR5_BOX], "clearance": 0.02},
    "timing": {"method": "search"},
}
#: The same on 300 roadmap points: its build alone takes about 2.4 s (1.7 GiB by its estimate),
#: so that two at once beside a stream of short requests on two cores run out of a 3 s budget.
OVER_BUDGET_SEARCH = {**SEARCH, "timing": {"method": "search", "search": {"roadmap_points": 300}}}
#: How a search that runs out of its budget ends: a 504 where the budget passes (in its build or
#: its local optimization), a 422 where its branch and bound spends its share of the budget (a
#: quarter of the time left after the build) without a grid path.
OUT_OF_BUDGET = (504, "the search found no grid path within its share of the time budget")


@pytest.mark.parametrize(
    "method, kind, grid_points, expected",
    [
        ("search", "free", None, True),
        ("collocation", "free", 20, True),
        ("jerk_limited", "waypoints", None, True),
        ("min_cost", "waypoints", None, True),
        ("min_cost", "waypoints", 1000, True),
        ("min_cost", "waypoints", 50, False),
        ("phase_plane", "waypoints", None, False),
        ("toppra", "waypoints", 5000, False),
    ],
)
def test_which_plannings_are_heavy(method, kind, grid_points, expected):
    assert heavy(method, kind, grid_points) is expected


def test_a_search_does_not_take_the_threads_of_the_short_requests():
    """One planning thread and no queue for the short requests, one heavy worker and no heavy
    queue: while a search runs, a short request is served, and a second heavy one is refused at
    once with 503 and Retry-After; the search itself answers within its budget or is refused at it."""
    app = create_app(Settings(preload_robots=False, plan_workers=1, plan_queue=0, plan_heavy_workers=1, plan_heavy_queue=0, plan_budget_s=3.0))

    async def scenario():
        async with httpx.AsyncClient(transport=httpx.ASGITransport(app=app), base_url="http://toptraj", timeout=30) as client:
            assert (await client.post("/v1/trajectories", json=TYPICAL)).status_code == 200  # the model is loaded
            search = asyncio.create_task(client.post("/v1/trajectories", json=SEARCH))
            await asyncio.sleep(0.5)
            short = await client.post("/v1/trajectories", json=TYPICAL)
            second = await client.post("/v1/trajectories", json={**SEARCH, "timing": {"method": "collocation"}, "path": {"kind": "free", "start": UR5_START, "goal": UR5_GOAL}})
            return short, second, await search

    async def run():
        async with app.router.lifespan_context(app):
            return await scenario()

    short, second, search = asyncio.run(run())
    assert short.status_code == 200, short.text[:300]
    assert second.status_code == 503 and "heavy planning" in second.json()["detail"] and second.headers["retry-after"] == "5"
    # a heavy planning holds its worker for seconds: the 503 asks for 5 s and names the job that waits its turn instead
    assert "retry in 5 s, or run it as a job, in the background: POST /v1/jobs" in second.json()["detail"], second.json()["detail"]
    # the search answers within its budget (its local optimization stopped at its share) or is
    # refused at it, depending on the machine's speed; never a better duration than the optimum's
    assert search.status_code in (200, 504) or search.json()["detail"].startswith(OUT_OF_BUDGET[1]), search.text[:300]
    if search.status_code == 200:
        assert search.json()["duration"] >= 0.95028 * (1 - 1e-6)


def _tree_rss(server: LiveServer) -> int:
    """Resident bytes of the server and every process under it."""
    root = psutil.Process(server.process.pid)
    total = 0
    for process in [root, *root.children(recursive=True)]:
        try:
            total += process.memory_info().rss
        except psutil.NoSuchProcess:
            continue
    return total


def test_two_searches_over_budget_leave_the_typical_request_served_and_the_server_its_cpu_and_memory():
    budget_s = 3.0
    with LiveServer(workers=2, TOPTRAJ_PLAN_BUDGET_S=str(budget_s)) as server:
        server.wait_until_idle()
        for _ in range(20):  # both processes warm
            assert server.request("POST", "/v1/trajectories", TYPICAL)[0] == 200
        server.wait_until_idle()
        warm = _tree_rss(server)
        statuses: list[int] = []
        ended: list[float] = []
        answered: list[float] = []
        done = threading.Event()

        def search() -> None:
            status, _, body = server.request("POST", "/v1/trajectories", OVER_BUDGET_SEARCH)
            statuses.append(status if status != 422 else json.loads(body)["detail"][: len(OUT_OF_BUDGET[1])])
            ended.append(time.monotonic())

        def stream() -> None:
            while not done.is_set():
                status = server.request("POST", "/v1/trajectories", TYPICAL)[0]
                answered.append(time.monotonic())
                assert status == 200
                time.sleep(0.02)

        searches = [threading.Thread(target=search) for _ in range(2)]
        streams = [threading.Thread(target=stream) for _ in range(2)]
        for thread in (*streams, *searches):
            thread.start()
        for thread in searches:
            thread.join()
        done.set()
        for thread in streams:
            thread.join()
        assert len(statuses) == 2 and set(statuses) <= set(OUT_OF_BUDGET), statuses
        # Typical requests are answered while both searches run (events, not a latency figure:
        # benchmarks/heavy_latency.py measures the p99 beside the idle one): a server that held
        # them behind the searches would answer none before the first search ends.
        before_end = sum(instant < min(ended) for instant in answered)
        assert before_end >= 10, f"{before_end} typical requests answered while the searches ran"
        # the work stops with the searches: under 0.5 CPU-s over the tree in the 2 s after both
        before = server.cpu_seconds()
        time.sleep(max(0.0, ended[-1] + 2.0 - time.monotonic()))
        used = server.cpu_seconds() - before
        assert used < 0.5, f"{used:.2f} CPU-s in the 2 s after the searches ended"
        # and the memory goes back: within 200 MB of the warm figure (waited for with a hang
        # guard: how soon a busy machine reaps the workers is not what is tested)
        give_up = max(ended) + 60.0
        while (held := _tree_rss(server)) - warm > 200e6 and time.monotonic() < give_up:
            time.sleep(0.1)
        assert held - warm < 200e6, f"{(held - warm) / 1e6:.0f} MB above the warm figure a minute after the searches ended"


def test_a_comparison_is_heavy_when_one_of_its_methods_is():
    path = {"waypoints": TYPICAL["path"]["waypoints"]}
    assert heavy_request(CompareRequest.model_validate({"robot": "ur5", "path": path, "methods": ["phase_plane", "min_cost"]}))
    assert not heavy_request(CompareRequest.model_validate({"robot": "ur5", "path": path, "methods": ["phase_plane", "quintic"]}))
    assert not heavy_request(TrajectoryRequest.model_validate(TYPICAL))
