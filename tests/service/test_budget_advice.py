"""A request past its time budget is told what to do instead, and doing it works: a synchronous
request as a job (the job's body given in the 504's words), a line of ``toptraj batch`` again
with ``--retry-failed`` and the larger ``--budget`` named, a line of ``POST /v1/batches`` alone as
a job; where the server allows nothing longer, the advice names its settings instead of a job
that would fail the same way."""

from __future__ import annotations

import json
import re
import time

import orjson
import pytest
from fastapi.testclient import TestClient

from tests.conftest import UR5_WAYPOINTS
from tests.service.test_batch_lines import InProcessPool, _by_line
from toptraj.planners import Deadline
from toptraj.service import budget_advice
from toptraj.service.app import create_app
from toptraj.service.batches import run_batch
from toptraj.service.jobs.work import WorkerSetup, _batch
from toptraj.service.settings import Settings

QUICK = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}}
#: Milliseconds of planning: past a budget of a microsecond, well within a job's.
COMPARE = {**QUICK, "methods": ["phase_plane", "quintic"]}


def _job_body(detail: str, request: dict) -> tuple[str, dict]:
    """The route and body that the advice of ``detail`` names, ``request`` put in its place."""
    found = re.search(r"POST (/v1/jobs) with (\{.*?\}) \(at most", detail)
    assert found, detail
    return found.group(1), json.loads(re.sub(r"<this (line's )?request>", json.dumps(request), found.group(2)))


def _done(client: TestClient, location: str, timeout_s: float = 120.0) -> dict:
    give_up = time.monotonic() + timeout_s
    while time.monotonic() < give_up:
        job = client.get(location).json()
        if job["status"] in {"done", "failed", "cancelled", "interrupted"}:
            return job
        time.sleep(0.05)
    raise AssertionError(f"{location} not done after {timeout_s} s")


@pytest.fixture(scope="module")
def tight(tmp_path_factory):
    """A server whose planning budget nothing fits in."""
    settings = Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("tight"), job_workers=1, plan_budget_s=1e-6)
    with TestClient(create_app(settings)) as client:
        yield client


@pytest.mark.parametrize(("kind", "request_body", "route"), [("trajectory", QUICK, "/v1/trajectories"), ("compare", COMPARE, "/v1/trajectories/compare")])
def test_a_synchronous_504_names_the_job_that_plans_it_and_that_job_does(tight, kind, request_body, route):
    response = tight.post(route, json=request_body)
    assert response.status_code == 504, response.text
    detail = response.json()["detail"]
    assert detail.startswith("planning exceeded its time budget of 1e-06 s; run it as a job"), detail
    job_route, job = _job_body(detail, request_body)
    assert set(job) == {kind, "budget_s"} and job["budget_s"] == 300
    submitted = tight.post(job_route, json=job)
    assert submitted.status_code == 202, submitted.text
    finished = _done(tight, submitted.headers["location"])
    assert finished["status"] == "done", finished
    answer = tight.get(submitted.headers["location"] + "/result").json()
    assert (answer["duration"] if kind == "trajectory" else answer["results"][0]["duration"]) > 0.5


def test_a_cell_past_its_budget_names_the_setting_that_gives_it_more_time(tight):
    arm = {"robot": "ur5", "waypoints": UR5_WAYPOINTS[:2]}
    cell = {"arms": [arm, {**arm, "base": {"position": [2.0, 0.0, 0.0]}}]}
    response = tight.post("/v1/cells", json=cell)
    assert response.status_code == 504, response.text
    assert response.json()["detail"] == (
        "planning exceeded its time budget of 1e-06 s; a cell is planned only within the server's planning budget, "
        "which its operator can raise with TOPTRAJ_PLAN_BUDGET_S"
    )


def test_no_job_is_advised_where_a_job_may_not_run_longer():
    advice = budget_advice.as_job("trajectory", 20.0, 300.0, 20.0)
    assert "POST /v1/jobs" not in advice and "TOPTRAJ_JOB_MAX_BUDGET_S" in advice
    assert "at most 3600" in budget_advice.larger_job_budget(300.0, 3600.0)
    assert "TOPTRAJ_JOB_MAX_BUDGET_S" in budget_advice.larger_job_budget(3600.0, 3600.0)


def test_a_batch_line_past_its_budget_names_the_retry_that_plans_it(tmp_path):
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text(json.dumps(QUICK) + "\n" + json.dumps({**QUICK, "robot": "nope"}) + "\n")
    run_batch(requests, output, budget_s=1e-9, pool=InProcessPool)
    rows = _by_line(output)
    assert (rows[1]["status"], rows[2]["status"]) == (504, 404)
    detail = rows[1]["body"]["detail"]
    found = re.search(r"run the same command again with --retry-failed --budget (\S+) \(at most 3600 s\)", detail)
    assert found, detail
    assert float(found.group(1)) == 60.0
    report = run_batch(requests, output, budget_s=float(found.group(1)), retry_failed=True, pool=InProcessPool)
    assert report.planned == 1 and _by_line(output)[1]["status"] == 200


def test_a_line_of_a_batch_job_past_its_budget_names_the_job_that_plans_it(tmp_path, monkeypatch):
    from toptraj.service.jobs import work

    monkeypatch.setattr(work, "BATCH_REQUEST_BUDGET_S", 1e-6)  # a line's budget, which nothing fits in
    monkeypatch.setattr(work, "MIN_LINE_BUDGET_S", 1e-9)
    request = orjson.dumps({"requests": [QUICK, COMPARE]}).decode()
    setup = WorkerSetup(str(tmp_path), 10, 1_000_000, 4, 50_000_000, job_budget_s=120.0, job_max_budget_s=900.0)
    results = orjson.loads(_batch(request, Deadline(60.0), setup))["results"]
    assert [row["status"] for row in results] == [504, 504]
    for row, kind, line in zip(results, ("trajectory", "compare"), (QUICK, COMPARE), strict=True):
        detail = row["body"]["detail"]
        assert "(at most 900 s)" in detail, detail
        route, job = _job_body(detail, line)
        assert route == "/v1/jobs" and job == {kind: line, "budget_s": 120}


def test_the_advised_job_budget_is_always_more_than_the_request_had():
    """A server whose planning budget exceeds a job's default (600 s against 300): the job advised
    gets five times the planning budget, within the job maximum."""
    assert '"budget_s": 3000}' in budget_advice.as_job("trajectory", 600.0, 300.0, 3600.0)
    assert '"budget_s": 3600}' in budget_advice.as_job("trajectory", 1000.0, 300.0, 3600.0)
    assert '"budget_s": 300}' in budget_advice.as_job("trajectory", 20.0, 300.0, 3600.0)
