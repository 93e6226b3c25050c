"""``toptraj batch``: request lines planned on Ray equal the service's answers one by one,
errors are lines too, a resumed batch plans nothing twice, and uploaded robots reach the Ray
workers (which cannot see the driver's upload store)."""

from __future__ import annotations

import json

import numpy as np
import orjson
import pytest

from tests.service.test_upload_store import PLAN, arm
from toptraj import robots
from toptraj.service.batches import run_batch
from toptraj.service.batches.lines import request_key, resume_output
from toptraj.service.planning import plan_request, render
from toptraj.service.schemas.trajectories import TrajectoryRequest

#: The directories of Ray's sessions on this machine (its default temporary directory), named
#: session_<date>_<time>_<pid of the process that started it>.
RAY_SESSIONS = "/tmp/ray/session_2*"

ray = pytest.importorskip("ray")  # the "ray" extra, which make test installs


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, object_store_memory=80 * 1024 * 1024, log_to_driver=False, configure_logging=False)
    yield
    ray.shutdown()


def _requests(count: int, seed: int = 3) -> list[str]:
    rng = np.random.default_rng(seed)
    lines = []
    for k in range(count):
        robot = "ur5" if k % 2 == 0 else "panda"
        dof = 6 if robot == "ur5" else 7
        limits = robots.load(robot).limits
        low, high = np.maximum(limits.position_lower, -2.0), np.minimum(limits.position_upper, 2.0)
        waypoints = rng.uniform(low, high, (3, dof)) * 0.8
        lines.append(json.dumps({"robot": robot, "path": {"waypoints": waypoints.tolist()}}))
    return lines


def _results(path) -> dict[int, dict]:
    return {row["line"]: row for row in map(json.loads, path.read_text().splitlines())}


def test_a_batch_equals_planning_each_request_alone(tmp_path):
    lines = _requests(6)
    requests = tmp_path / "requests.jsonl"
    requests.write_text("\n".join(lines) + "\n")
    report = run_batch(requests, tmp_path / "results.jsonl")
    assert (report.total, report.planned, report.skipped) == (6, 6, 0)
    results = _results(tmp_path / "results.jsonl")
    assert sorted(results) == list(range(1, 7))
    for number, text in enumerate(lines, start=1):
        request = TrajectoryRequest.model_validate_json(text)
        alone = orjson.loads(render(plan_request(request), request)[0])
        row = results[number]
        assert row["status"] == 200 and row["key"] == request_key(text)
        assert row["body"]["duration"] == alone["duration"]
        for key in ("t", "q", "qd", "qdd", "tau"):
            np.testing.assert_array_equal(np.array(row["body"]["samples"][key]), np.array(alone["samples"][key]))


def test_errors_are_lines_too(tmp_path):
    requests = tmp_path / "requests.jsonl"
    requests.write_text(
        "not json\n"
        + json.dumps({"robot": "nope", "path": {"waypoints": [[0.0], [1.0]]}}) + "\n\n"
        + json.dumps({"robot": "ur5", "path": {"waypoints": [[0.0] * 6]}}) + "\n"
        + json.dumps({"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [9.0] + [0.0] * 5]}}) + "\n"
    )
    run_batch(requests, tmp_path / "results.jsonl")
    results = _results(tmp_path / "results.jsonl")
    assert {n: r["status"] for n, r in results.items()} == {1: 422, 2: 404, 3: 422, 4: 422, 5: 422}
    assert "outside the limits" in results[5]["body"]["detail"] and results[2]["body"]["title"] == "Unknown robot"


def test_a_resumed_batch_plans_nothing_twice(tmp_path):
    lines = _requests(5, seed=11)
    requests, output = tmp_path / "requests.jsonl", tmp_path / "results.jsonl"
    requests.write_text("\n".join(lines[:3]) + "\n")
    assert run_batch(requests, output).planned == 3
    # the file grows, with a request repeated in another formatting, and the last result line
    # was cut short by an interrupted run
    repeated = json.dumps(json.loads(lines[0]), indent=1).replace("\n", " ")
    requests.write_text("\n".join([*lines, repeated]) + "\n")
    text = output.read_text()
    output.write_text(text + text.splitlines()[-1][:40])
    report = run_batch(requests, output)
    assert (report.total, report.skipped, report.planned) == (6, 3, 3)
    rows = [json.loads(r) for r in output.read_text().splitlines()]
    assert sorted(r["line"] for r in rows) == [1, 2, 3, 4, 5, 6]
    assert {r["line"]: r["key"] for r in rows} == {n: request_key(line) for n, line in enumerate([*lines, repeated], start=1)}
    assert run_batch(requests, output).planned == 0
    assert resume_output(output) == {n: 200 for n in range(1, 7)}


def test_an_uploaded_robot_reaches_the_ray_workers(tmp_path):
    robots.configure_uploads(tmp_path / "driver-store")  # the workers do not see this store
    try:
        robots.register_urdf(arm(7.0), "batch_arm")
        body = {"robot": "batch_arm", **PLAN}
        requests = tmp_path / "requests.jsonl"
        requests.write_text(json.dumps(body) + "\n")
        run_batch(requests, tmp_path / "results.jsonl")
        row = _results(tmp_path / "results.jsonl")[1]
        assert row["status"] == 200, row["body"]
        request = TrajectoryRequest.model_validate(body)
        assert row["body"]["duration"] == orjson.loads(render(plan_request(request), request)[0])["duration"]
    finally:
        robots.configure_uploads(tmp_path / "elsewhere")


def test_a_batch_over_http_answers_each_request_in_order(client):
    good = json.loads(_requests(1)[0])
    bad = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [9.0] + [0.0] * 5]}}
    compare = {"robot": "ur5", "path": good["path"], "methods": ["phase_plane", "quintic"]}
    response = client.post("/v1/batches", json={"requests": [good, bad, compare]})
    assert response.status_code == 202, response.text
    location = response.headers["location"]
    import time

    for _ in range(600):
        job = client.get(location).json()
        if job["status"] in ("done", "failed"):
            break
        time.sleep(0.1)
    assert job["status"] == "done" and job["kind"] == "batch", job
    results = job["result"]["results"]
    assert [(r["line"], r["status"]) for r in results] == [(1, 200), (2, 422), (3, 200)]
    request = TrajectoryRequest.model_validate(good)
    assert results[0]["body"]["duration"] == orjson.loads(render(plan_request(request), request)[0])["duration"]
    assert [r["method"] for r in results[2]["body"]["results"]] == ["phase_plane", "quintic"]


def test_a_bad_request_in_a_batch_is_refused_at_once(client):
    response = client.post("/v1/batches", json={"requests": [{"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 6]}}, {"robot": "ur5", "path": {"waypoints": "no"}}]})
    assert response.status_code == 422 and "requests[1]" in response.text


def test_a_batch_over_http_runs_on_ray_when_the_server_has_an_address(tmp_path):
    """``TOPTRAJ_RAY_ADDRESS=local``: the job hands its requests to a Ray it starts."""
    import glob
    import time

    import psutil
    from fastapi.testclient import TestClient

    from toptraj.service.app import create_app
    from toptraj.service.settings import Settings

    good = json.loads(_requests(2)[1])
    before = set(glob.glob(RAY_SESSIONS))
    settings = Settings(preload_robots=False, data_dir=tmp_path, ray_address="local")
    with TestClient(create_app(settings)) as client:
        location = client.post("/v1/batches", json={"requests": [good, {"robot": "nope", **PLAN}]}).headers["location"]
        ours: set[int] = set()  # every process this test started while the job ran
        for _ in range(1200):
            ours |= {process.pid for process in psutil.Process().children(recursive=True)}
            job = client.get(location).json()
            if job["status"] in ("done", "failed"):
                break
            time.sleep(0.1)
        # The job started a Ray session of its own: Ray names each session's directory after
        # the process that started it, here one of this test's (the job's worker), whatever
        # other Ray sessions the machine starts meanwhile.
        started = {int(path.rsplit("_", 1)[1]) for path in set(glob.glob(RAY_SESSIONS)) - before}
    assert job["status"] == "done", job
    assert [(r["line"], r["status"]) for r in job["result"]["results"]] == [(1, 200), (2, 404)]
    assert started & ours, (started, ours)


def _typical(method: str, shift: float) -> str:
    """The typical request (``warmup.TYPICAL``) timed by ``method``, its first waypoint moved."""
    from toptraj.service.warmup import TYPICAL

    body = json.loads(json.dumps(TYPICAL))
    body["timing"]["method"] = method
    body["path"]["waypoints"][0][0] += shift
    return json.dumps(body)


def test_each_ray_worker_is_prepared_once_and_plans_min_cost_in_itself(tmp_path):
    """A worker is prepared once whatever the lines it answers, and its ``min_cost`` lines run
    inline: no fork server, no child process per line (the cause of seconds per line in a
    Ray worker); their answers equal the service's own."""
    lines = [_typical(("min_cost", "phase_plane")[k % 2], 0.02 * k) for k in range(8)]
    requests = tmp_path / "requests.jsonl"
    requests.write_text("\n".join(lines) + "\n")
    assert run_batch(requests, tmp_path / "results.jsonl").planned == 8
    results = _results(tmp_path / "results.jsonl")
    for number in (1, 2, 7):
        request = TrajectoryRequest.model_validate_json(lines[number - 1])
        alone = orjson.loads(render(plan_request(request), request)[0])
        assert results[number]["status"] == 200, results[number]
        np.testing.assert_allclose(results[number]["body"]["duration"], alone["duration"], rtol=1e-9)

    def state(_: int) -> tuple[int, int, list[str]]:
        import os
        import time

        import psutil

        from toptraj.service.batches.prepare import times_prepared

        time.sleep(0.3)  # both workers busy at once: each probe on its own worker
        return os.getpid(), times_prepared(), [" ".join(child.cmdline())[:80] for child in psutil.Process().children(recursive=True)]

    probe = ray.remote(num_cpus=1)(state)
    seen = {pid: (times, children) for pid, times, children in ray.get([probe.remote(k) for k in range(4)])}
    prepared = {pid: (times, children) for pid, (times, children) in seen.items() if times}
    assert prepared, seen  # the workers that answered the lines
    assert all(times == 1 and children == [] for times, children in prepared.values()), prepared
