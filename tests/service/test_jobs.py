"""Background jobs (``/v1/jobs``): answers that survive a restart, interrupted jobs, cancelling
that stops the work, progress, budgets, the bounds of the job store, and the Geering free-path
example as a job while synchronous requests are served."""

from __future__ import annotations

import json
import os
import re
import signal
import time

import psutil
import pytest
from fastapi.testclient import TestClient

from tests.conftest import UR5_WAYPOINTS
from tests.live_server import LiveServer
from tests.paths import DATA, ROOT
from toptraj.planners import BudgetExceeded, Deadline
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.execution.isolated import run_isolated
from toptraj.service.app import create_app
from toptraj.service.jobs.store import JobStore
from toptraj.service.settings import Settings

EXAMPLES = ROOT / "examples"

QUICK = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}}
#: A free-path collocation of a six-joint arm on a fine grid: minutes of SLSQP in its worker
#: process, so it is still running whenever a test looks.
#: A planning that runs for seconds on any machine and cannot shorten itself to a budget:
#: min_cost at its largest grid on ur5 (one convex program in a worker process).
SLOW = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
    "timing": {"method": "min_cost", "grid_points": 4000},
}
ENDED = {"done", "failed", "cancelled", "interrupted"}


def _settings(data_dir, **overrides) -> Settings:
    return Settings(preload_robots=False, data_dir=data_dir, job_workers=1, **overrides)


def _submit(client, body: dict, **fields) -> str:
    response = client.post("/v1/jobs", json={**body, **fields})
    assert response.status_code == 202, response.text
    assert response.headers["location"] == f"/v1/jobs/{response.json()['id']}"
    return response.json()["id"]


class _Looks:
    """Counts the dispatcher's looks for work in a job store: calls of ``method`` (``has_queued``,
    made only with a free slot, or ``claim``) whose answer satisfies ``counts``."""

    def __init__(self, monkeypatch, store: JobStore, method: str, counts=lambda answer: True):
        self.calls = 0
        original = getattr(store, method)

        def counted(*args, **kwargs):
            answer = original(*args, **kwargs)
            if counts(answer):
                self.calls += 1
            return answer

        monkeypatch.setattr(store, method, counted)

    def wait_for(self, calls: int, hang_s: float = 60.0) -> None:
        """Return once ``calls`` more looks are counted (a hang guard only bounds the wait)."""
        target = self.calls + calls
        give_up = time.monotonic() + hang_s
        while self.calls < target:
            assert time.monotonic() < give_up, f"{self.calls} looks for work, waiting for {target}"
            time.sleep(0.01)


def _wait(client, job_id: str, statuses=ENDED, timeout_s: float = 120.0, every_s: float = 0.05) -> dict:
    """The job once its status is one of ``statuses``."""
    give_up = time.monotonic() + timeout_s
    while time.monotonic() < give_up:
        job = client.get(f"/v1/jobs/{job_id}").json()
        if job["status"] in statuses:
            return job
        time.sleep(every_s)
    raise AssertionError(f"job {job_id} still {job['status']} after {timeout_s} s: {job['progress']}")


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with TestClient(create_app(_settings(tmp_path_factory.mktemp("jobs")))) as test_client:
        yield test_client


# --- the resource --------------------------------------------------------------------------


def test_a_job_answers_what_the_synchronous_endpoint_answers(client):
    job_id = _submit(client, {"trajectory": QUICK})
    job = _wait(client, job_id)
    assert job["status"] == "done", job
    assert job["progress"] == {"fraction": 1.0, "stage": "done"}
    assert job["created_at"] <= job["started_at"] <= job["finished_at"]
    synchronous = client.post("/v1/trajectories", json=QUICK).json()
    for key in ("duration", "samples", "peak_utilization", "phase_plane"):
        assert job["result"][key] == synchronous[key]
    alone = client.get(f"/v1/jobs/{job_id}/result")
    assert alone.status_code == 200 and alone.json() == job["result"]


def test_a_compare_job(client):
    body = {**QUICK, "methods": ["phase_plane", "quintic"]}
    job = _wait(client, _submit(client, {"compare": body}))
    synchronous = client.post("/v1/trajectories/compare", json=body).json()
    assert [row["duration"] for row in job["result"]["results"]] == [row["duration"] for row in synchronous["results"]]


def test_a_failed_job_carries_the_problem_of_the_synchronous_endpoint(client):
    # Gravity holds the vertical arm's shoulder above a torque limit cut to 1 %.
    body = {
        "robot": "yamamoto_2r",
        "path": {"kind": "waypoints", "waypoints": [[0.5, 0.0], [0.6, 0.1]]},
        "timing": {"limits": {"torque_scale": 0.01}},
    }
    synchronous = client.post("/v1/trajectories", json=body)
    assert synchronous.status_code == 422
    job = _wait(client, _submit(client, {"trajectory": body}))
    assert job["status"] == "failed" and job["result"] is None
    assert job["error"] == synchronous.json()
    assert {"s", "joint"} <= job["error"].keys()
    alone = client.get(f"/v1/jobs/{job['id']}/result")
    assert alone.status_code == 422 and alone.json() == synchronous.json()


def test_a_job_on_an_uploaded_robot(client):
    upload = client.post("/v1/robots", json={"name": "job_pendulum", "urdf": (DATA / "pendulum_1r.urdf").read_text()})
    assert upload.status_code == 201, upload.text
    body = {"robot": "job_pendulum", "path": {"kind": "waypoints", "waypoints": [[0.0], [1.0]]}}
    job = _wait(client, _submit(client, {"trajectory": body}))
    assert job["status"] == "done", job["error"]
    assert job["result"]["robot"] == "job_pendulum"


@pytest.mark.parametrize(
    "body, status, words",
    [
        ({}, 422, "exactly one of `trajectory`"),
        ({"trajectory": QUICK, "compare": {**QUICK, "methods": ["toppra"]}}, 422, "exactly one of"),
        ({"trajectory": QUICK, "budget_s": 3601}, 422, "budget_s <= 3600"),
        ({"trajectory": QUICK, "budget_s": 0}, 422, "budget_s"),
        ({"trajectory": {**QUICK, "robot": "no_such_arm"}}, 404, "no_such_arm"),
        ({"trajectory": {**QUICK, "path": {"waypoints": [[0.0, "x"]]}}}, 422, "trajectory.path.waypoints[0][1]"),
        # Stored to be computed later: held to the schema without coercion (false is no number).
        ({"trajectory": {**QUICK, "timing": {"limit_margin": False}}}, 422, "trajectory.timing.limit_margin"),
        ({"trajectory": None}, 422, "trajectory"),
    ],
)
def test_a_bad_submission_is_refused_at_once(client, body, status, words):
    response = client.post("/v1/jobs", json=body)
    assert response.status_code == status, response.text
    assert response.headers["content-type"] == "application/problem+json"
    assert words in response.json()["detail"]


GEERING_FREE = {"robot": "geering_2r", "path": {"kind": "free", "start": [0.0, 0.0], "goal": [0.76, 0.0]}, "timing": {"method": "search"}}


@pytest.mark.parametrize(
    "body, words",
    [
        ({**QUICK, "path": {"waypoints": [[0.0, 0.0], [1.0, 1.0]]}}, "path.waypoints[0] has 2 values; ur5 has 6 joints"),
        ({**GEERING_FREE, "path": {**GEERING_FREE["path"], "goal": [9.0, 0.0]}}, "path.goal[0] = 9 is outside the limits"),
        ({**GEERING_FREE, "timing": {"method": "collocation"}, "path": {**GEERING_FREE["path"], "start": [-9.0, 0.0]}},
         "path.start[0] = -9 is outside the limits"),
        ({**GEERING_FREE, "path": {**GEERING_FREE["path"], "obstacles": [{"kind": "sphere", "center": [0.5, 0.0, 0.0], "radius": 0.3}]}},
         "at path.start, link "),
        ({**QUICK, "timing": {"method": "min_cost", "grid_points": 20_000}}, "use timing.grid_points <= "),
    ],
)
def test_a_job_the_planner_would_refuse_before_any_work_is_refused_at_submission(client, body, words):
    """What the synchronous endpoint refuses before planning (the problem's own checks, a free
    path's ends, the memory estimate) is refused when the job is submitted, with the same
    problem, rather than queued to fail later."""
    synchronous = client.post("/v1/trajectories", json=body)
    assert synchronous.status_code == 422 and words in synchronous.json()["detail"], synchronous.text[:300]
    submitted = client.post("/v1/jobs", json={"trajectory": body})
    assert submitted.status_code == 422, submitted.text[:300]
    assert submitted.json() == synchronous.json()


def test_an_unknown_job_is_a_404(client):
    for method, path in [("GET", "/v1/jobs/0123"), ("GET", "/v1/jobs/0123/result"), ("DELETE", "/v1/jobs/0123")]:
        response = client.request(method, path)
        assert response.status_code == 404 and response.json()["title"] == "Unknown job"


def test_the_list_is_paginated_newest_first(client):
    ids = [_submit(client, {"trajectory": QUICK}) for _ in range(3)]
    for job_id in ids:
        _wait(client, job_id)
    first = client.get("/v1/jobs", params={"limit": 2}).json()
    assert [job["id"] for job in first["jobs"]] == ids[::-1][:2]
    assert "result" not in first["jobs"][0]
    second = client.get("/v1/jobs", params={"limit": 2, "cursor": first["next_cursor"]}).json()
    assert second["jobs"][0]["id"] == ids[0]
    assert client.get("/v1/jobs", params={"limit": 101}).status_code == 422
    assert client.get("/v1/jobs", params={"cursor": "x"}).status_code == 422
    for cursor in ("99999999999999999999", "\u00b2"):  # beyond 64 bits; a digit to str.isdigit, not to int()
        refused = client.get("/v1/jobs", params={"cursor": cursor})
        assert refused.status_code == 422 and "is not a next_cursor" in refused.json()["detail"], refused.text
    done = client.get("/v1/jobs", params={"status": "done", "limit": 100}).json()["jobs"]
    assert done and all(job["status"] == "done" for job in done)


# --- budgets, queueing and cancelling --------------------------------------------------------


def test_a_job_over_its_budget_fails_with_a_504(client):
    job = _wait(client, _submit(client, {"trajectory": SLOW}, budget_s=1.0))
    assert job["status"] == "failed"
    assert job["error"]["status"] == 504 and "budget of 1 s" in job["error"]["detail"]
    assert client.get(f"/v1/jobs/{job['id']}/result").status_code == 504


def test_a_queued_job_cancelled_never_runs(client, monkeypatch):
    looks = _Looks(monkeypatch, client.app.state.jobs.store, "has_queued")
    running = _submit(client, {"trajectory": SLOW})
    _wait(client, running, {"running"})
    queued = _submit(client, {"trajectory": QUICK})
    assert client.get(f"/v1/jobs/{queued}").json()["status"] == "queued"  # one job worker, taken
    # The synchronous endpoint answers while the job worker is busy.
    assert client.post("/v1/trajectories", json=QUICK).status_code == 200
    cancelled = client.delete(f"/v1/jobs/{queued}")
    assert cancelled.status_code == 200 and cancelled.json()["status"] == "cancelled"
    assert client.delete(f"/v1/jobs/{running}").json()["status"] == "cancelled"
    # The worker is free: two looks for work with a free slot, the second after any claim the
    # first could make (a queued job would have been claimed by then).
    looks.wait_for(2)
    job = client.get(f"/v1/jobs/{queued}").json()
    assert job["status"] == "cancelled" and job["started_at"] is None and job["result"] is None
    assert client.get(f"/v1/jobs/{queued}/result").status_code == 409
    # Deleting it again removes the cancelled job.
    assert client.delete(f"/v1/jobs/{queued}").status_code == 204
    assert client.get(f"/v1/jobs/{queued}").status_code == 404


def test_an_ended_job_is_deleted_with_its_answer(client):
    job_id = _submit(client, {"trajectory": QUICK})
    _wait(client, job_id)
    store = client.app.state.jobs.store
    jobs, stored = store.usage()
    assert client.get(f"/v1/jobs/{job_id}/result").status_code == 200
    response = client.delete(f"/v1/jobs/{job_id}")
    assert response.status_code == 204 and response.content == b""
    assert client.get(f"/v1/jobs/{job_id}").status_code == 404
    assert client.get(f"/v1/jobs/{job_id}/result").status_code == 404
    assert job_id not in [job["id"] for job in client.get("/v1/jobs", params={"limit": 100}).json()["jobs"]]
    assert store.usage()[0] == jobs - 1 and store.usage()[1] < stored  # the answer's bytes are gone too
    assert client.delete(f"/v1/jobs/{job_id}").status_code == 404


def test_the_queue_is_bounded(tmp_path):
    with TestClient(create_app(_settings(tmp_path, job_queue=1))) as client:
        running = _submit(client, {"trajectory": SLOW})
        _wait(client, running, {"running"})
        queued = _submit(client, {"trajectory": SLOW})
        refused = client.post("/v1/jobs", json={"trajectory": SLOW})
        assert refused.status_code == 503 and refused.headers["retry-after"]
        for job_id in (queued, running):
            client.delete(f"/v1/jobs/{job_id}")


def test_progress_advances_on_a_collocation_job(client):
    """The Geering example's collocation reports its stages (its initial guesses, the re-timing,
    the switching times, the sampling) as it goes: watched to the end, the fractions never go
    back. Progress is written at most every ``PROGRESS_WRITE_S``, and the 15 guesses may all
    fit in one such interval, so not every stage is seen."""
    example = json.loads((EXAMPLES / "geering_free_motion.json").read_text())
    job_id = _submit(client, {"trajectory": example})
    seen: dict[str, float] = {}
    give_up = time.monotonic() + 120
    while time.monotonic() < give_up:
        job = client.get(f"/v1/jobs/{job_id}").json()
        if job["status"] not in ("queued", "running"):
            break
        fraction, stage = job["progress"]["fraction"], job["progress"]["stage"]
        assert fraction >= max(seen.values(), default=0.0), (stage, fraction, seen)
        seen.setdefault(stage, fraction)
        time.sleep(0.02)
    assert job["status"] == "done" and job["progress"] == {"fraction": 1.0, "stage": "done"}, job
    stages = {stage: fraction for stage, fraction in seen.items() if stage not in ("", "starting")}
    known = ("collocation: ", "re-timing along the collocation's path: ", "refining the switching times", "sampling")
    assert len(stages) >= 2 and all(stage.startswith(known) for stage in stages), seen
    assert all(stage.endswith(" of 15") for stage in stages if stage.startswith("collocation: guess ")), seen
    fractions = list(stages.values())
    assert fractions == sorted(fractions) and len(set(fractions)) == len(fractions), seen
    # The first guess starts at 0: seen when the machine is slow enough for a poll to catch it.
    assert all(0.0 <= fraction < 1.0 for fraction in fractions), seen


def _report_three(progress) -> str:
    for k in range(3):
        progress(k / 3, f"step {k + 1} of 3")
    return "answer"


def test_progress_crosses_the_worker_pipe_and_maps_onto_its_part():
    reports = []
    deadline = Deadline(60, progress=lambda fraction, stage: reports.append((fraction, stage)))
    part = deadline.within(0.5, 1.0, "second half")
    assert run_isolated(_report_three, deadline=part, progress=True) == "answer"
    assert [stage for _, stage in reports] == [f"second half: step {k} of 3" for k in (1, 2, 3)]
    assert [fraction for fraction, _ in reports] == pytest.approx([0.5, 0.5 + 0.5 / 3, 0.5 + 1 / 3])
    part.cancel()
    with pytest.raises(BudgetExceeded):
        deadline.check()  # a part shares its deadline's end and cancellation
    assert NO_DEADLINE.within(0.0, 0.5) is NO_DEADLINE  # nobody listens: the same object


# --- several server processes on one store ---------------------------------------------------


def test_processes_on_one_store_share_the_job_workers_and_the_cancelling(tmp_path, monkeypatch):
    """Two apps on one data directory, as two server processes would be: at most
    ``job_workers`` jobs run over both, and a DELETE through one stops the work of the other."""
    with TestClient(create_app(_settings(tmp_path))) as first, TestClient(create_app(_settings(tmp_path))) as second:
        refused = [_Looks(monkeypatch, client.app.state.jobs.store, "claim", lambda job: job is None) for client in (first, second)]
        one = _submit(first, {"trajectory": SLOW})
        two = _submit(second, {"trajectory": SLOW})
        _wait(second, one, {"running"})
        workers = _job_workers()
        assert len(workers) == 1
        # The dispatchers have looked for work three times since, and the shared limit refused
        # them each time.
        target = sum(looks.calls for looks in refused) + 3
        give_up = time.monotonic() + 60.0
        while sum(looks.calls for looks in refused) < target:
            assert time.monotonic() < give_up, "the dispatchers stopped looking for work"
            time.sleep(0.01)
        assert second.get(f"/v1/jobs/{two}").json()["status"] == "queued"
        clients = {id(client.app.state.jobs): client for client in (first, second)}
        (runner,) = [client.app.state.jobs for client in (first, second) if client.app.state.jobs.running_here()]
        assert runner.running_here() == [one]
        other = next(client for key, client in clients.items() if key != id(runner))
        assert other.delete(f"/v1/jobs/{one}").json()["status"] == "cancelled"
        assert not _still_computing(workers, 1.0)
        give_up = time.monotonic() + GONE_GUARD_S  # a hang guard: the runner forgets the job once its worker is gone
        while one in runner.running_here() and time.monotonic() < give_up:
            time.sleep(0.02)
        assert one not in runner.running_here()
        _wait(first, two, {"running"})
        first.delete(f"/v1/jobs/{two}")


# --- restarts -----------------------------------------------------------------------------


def test_a_finished_job_is_read_after_a_restart_and_running_ones_are_interrupted(tmp_path):
    with TestClient(create_app(_settings(tmp_path))) as before:
        done = _submit(before, {"trajectory": QUICK})
        answer = _wait(before, done)["result"]
        running = _submit(before, {"trajectory": SLOW})
        _wait(before, running, {"running"})
        queued = _submit(before, {"trajectory": QUICK})
        workers = _job_workers()
        assert workers
    # The server stopped: its job worker is gone, the running job is interrupted.
    assert not _still_computing(workers, 1.0)
    with TestClient(create_app(_settings(tmp_path))) as after:
        assert after.get(f"/v1/jobs/{done}").json()["result"] == answer
        job = after.get(f"/v1/jobs/{running}").json()
        assert job["status"] == "interrupted" and job["error"]["title"] == "Job interrupted"
        result = after.get(f"/v1/jobs/{running}/result")  # no answer will ever come: said so, with what to do
        assert result.status_code == 409 and result.json()["detail"].endswith("has no answer; submit its request again (POST /v1/jobs)")
        # A job still queued when the server stopped runs after the restart.
        assert _wait(after, queued)["status"] == "done"


def _job_workers(pid: int | None = None, timeout_s: float = 60.0) -> list[psutil.Process]:
    """The worker processes of the fork server of process ``pid`` (default this one), once
    there is one: a job counts as running from its claim, a moment before its worker forks."""
    give_up = time.monotonic() + timeout_s
    while True:
        root = psutil.Process(pid)
        servers = [child for child in root.children() if "forkserver" in " ".join(child.cmdline())]
        workers = [worker for server in servers for worker in server.children()]
        if workers or time.monotonic() > give_up:
            return workers
        time.sleep(0.02)


def _workers_of(server: LiveServer) -> list[psutil.Process]:
    return _job_workers(server.process.pid)


#: How long a stopped worker may take to disappear before the test gives up (a hang guard: a
#: worker that computes on is caught by its CPU time long before).
GONE_GUARD_S = 60.0


def _still_computing(processes: list[psutil.Process], cpu_s: float) -> list[psutil.Process]:
    """Those of ``processes`` that compute on: each still running after it used ``cpu_s``
    CPU-seconds more from now, or after ``GONE_GUARD_S`` (a zombie, dead but not yet reaped,
    computes nothing). CPU time, not wall time: a busy machine slows how soon a process is
    reaped, not how much a worker that was stopped computes."""

    def cpu(process: psutil.Process) -> float:
        try:
            times = process.cpu_times()
            return times.user + times.system
        except psutil.NoSuchProcess:
            return 0.0

    start = {process.pid: cpu(process) for process in processes}
    give_up = time.monotonic() + GONE_GUARD_S
    while True:
        alive, computing = [], []
        for process in processes:
            try:
                if process.is_running() and process.status() != psutil.STATUS_ZOMBIE:
                    alive.append(process)
                    if cpu(process) - start[process.pid] > cpu_s:
                        computing.append(process)
            except psutil.NoSuchProcess:
                pass
        if not alive or computing or time.monotonic() > give_up:
            return alive
        time.sleep(0.02)


def _live_job(server: LiveServer, method: str, path: str, body: dict | None = None) -> tuple[int, dict]:
    status, _, content = server.request(method, path, body)
    return status, json.loads(content)


@pytest.fixture(scope="module")
def live_env(tmp_path_factory) -> dict[str, str]:
    """Settings of the real servers of this module, all on one data directory."""
    return {
        "TOPTRAJ_DATA_DIR": str(tmp_path_factory.mktemp("live-jobs")),
        "TOPTRAJ_PRELOAD_ROBOTS": "false",
        "TOPTRAJ_JOB_WORKERS": "1",
    }


@pytest.fixture(scope="module")
def server(live_env):
    with LiveServer(**live_env) as live:
        yield live


def test_a_killed_server_leaves_its_running_jobs_interrupted_and_its_answers_kept(live_env, request):
    first = LiveServer(**live_env).__enter__()
    try:
        status, done = _live_job(first, "POST", "/v1/jobs", {"trajectory": QUICK})
        assert status == 202
        status, running = _live_job(first, "POST", "/v1/jobs", {"trajectory": SLOW})
        give_up = time.monotonic() + 120
        while _live_job(first, "GET", f"/v1/jobs/{done['id']}")[1]["status"] != "done" and time.monotonic() < give_up:
            time.sleep(0.1)
        while _live_job(first, "GET", f"/v1/jobs/{running['id']}")[1]["status"] != "running" and time.monotonic() < give_up:
            time.sleep(0.1)
        workers = _workers_of(first)
        assert len(workers) == 1
    finally:
        first.process.send_signal(signal.SIGKILL)  # no shutdown at all
        first.process.wait()
    # Its job worker does not compute on for nobody.
    assert not _still_computing(workers, 5.0)
    # A server on the same data directory (started now, or already running and sweeping every
    # few seconds) finds the job's process gone.
    second = request.getfixturevalue("server")
    give_up = time.monotonic() + 30
    path = f"/v1/jobs/{running['id']}"
    while (job := _live_job(second, "GET", path)[1])["status"] == "running" and time.monotonic() < give_up:
        time.sleep(0.1)
    assert job["status"] == "interrupted", job
    status, job = _live_job(second, "GET", f"/v1/jobs/{done['id']}")
    assert job["status"] == "done" and job["result"]["duration"] > 0


# --- the work stops --------------------------------------------------------------------------


def test_cancelling_a_running_job_stops_its_work(server):
    server.wait_until_idle()
    status, job = _live_job(server, "POST", "/v1/jobs", {"trajectory": SLOW})
    assert status == 202
    give_up = time.monotonic() + 60
    while _live_job(server, "GET", f"/v1/jobs/{job['id']}")[1]["status"] != "running" and time.monotonic() < give_up:
        time.sleep(0.05)
    workers = _workers_of(server)
    assert len(workers) == 1
    before = server.cpu_seconds()
    give_up = time.monotonic() + 60.0  # a hang guard
    while server.cpu_seconds() - before <= 0.1:  # the job computes
        assert time.monotonic() < give_up, "the job does not compute"
        time.sleep(0.05)
    status, job = _live_job(server, "DELETE", f"/v1/jobs/{job['id']}")
    assert status == 200 and job["status"] == "cancelled"
    cancelled = time.monotonic()
    assert not _still_computing(workers, 1.0)
    time.sleep(max(0.0, cancelled + 1.0 - time.monotonic()))
    before = server.cpu_seconds()
    time.sleep(1.0)
    used = server.cpu_seconds() - before
    assert used < 0.1, f"{used:.2f} CPU-s in the second after the job was cancelled"


# --- the Geering example ---------------------------------------------------------------------


@pytest.mark.slow
def test_the_geering_free_path_example_runs_as_a_job_while_requests_are_served(client):
    """The shipped example as it is (a collocation with its switching-time refinement, some
    seconds), with the synchronous endpoint answering meanwhile and the job's progress
    reported by stage."""
    example = json.loads((EXAMPLES / "geering_free_motion.json").read_text())
    job_id = _submit(client, {"trajectory": example}, budget_s=3600)
    served, stages, next_request = 0, set(), time.monotonic()
    while (job := client.get(f"/v1/jobs/{job_id}").json())["status"] not in ENDED:
        stages.add(job["progress"]["stage"])
        if job["status"] == "running" and time.monotonic() >= next_request:
            # Now and then only: on two busy cores, requests in a row would halve the job's share.
            response = client.post("/v1/trajectories", json=QUICK)
            assert response.status_code == 200, response.text
            served += 1
            next_request = time.monotonic() + 2.0
        time.sleep(0.05)
    assert job["status"] == "done", job["error"]
    # progress by stage: the collocation's guesses, its path re-timed, its switching times refined
    # (how many of them a poll sees depends on the machine's speed; at least one past the start)
    worked = {stage for stage in stages if stage.startswith(("collocation", "re-timing", "refining"))}
    assert served >= 1 and worked, (served, stages)
    # Jeong & Lee's type-3 motion, T = 0.9755 s in the paper; with the elbow free the faster of
    # the goals one revolution apart is answered (the elbow returning, 0.974963 s)
    assert job["result"]["duration"] == pytest.approx(0.9755, rel=1e-2)
    assert job["result"]["solver"]["duration"] == pytest.approx(0.9755, rel=1e-2)


def test_the_store_keeps_the_newest_jobs_within_its_bounds(tmp_path):
    store = JobStore(tmp_path, max_jobs=3, max_age_s=3600, max_bytes=10_000)

    def finished(size: int) -> str:
        job = store.submit("trajectory", "{}", 10.0, max_queued=10)
        claimed = store.claim("here|1|x", max_running=1)
        assert claimed.id == job.id
        assert store.finish(job.id, "here|1|x", "done", b"x" * size)
        return job.id

    ids = [finished(100) for _ in range(5)]
    assert [job.id for job in store.jobs(10)] == ids[::-1][:3]
    big = [finished(4_000) for _ in range(3)]  # 12 kB of answers: the oldest goes
    assert [job.id for job in store.jobs(10)] == big[::-1][:2]
    assert store.usage()[1] <= 10_000
    aged = JobStore(tmp_path, max_jobs=3, max_age_s=1e-3, max_bytes=10_000)
    time.sleep(0.01)
    aged.prune()
    assert aged.jobs(10) == []
    assert os.path.getsize(tmp_path / "jobs.sqlite3") < 200_000


def test_a_job_that_ends_last_keeps_its_answer_over_those_ended_before(tmp_path):
    """The store's bound removes the jobs that ended first: a job submitted first but ended
    last keeps its answer (by submission order it went at once, a 404 to its client)."""
    store = JobStore(tmp_path, max_jobs=3, max_age_s=3600, max_bytes=10_000)
    first = store.submit("trajectory", "{}", 10.0, max_queued=10)
    assert store.claim("here|1|x", max_running=5).id == first.id
    later = []
    for _ in range(2):
        job = store.submit("trajectory", "{}", 10.0, max_queued=10)
        assert store.claim("here|1|x", max_running=5).id == job.id
        assert store.finish(job.id, "here|1|x", "done", b"x")
        later.append(job.id)
    assert store.finish(first.id, "here|1|x", "done", b"answer")
    waiting = store.submit("trajectory", "{}", 10.0, max_queued=10)  # four jobs: one ended goes
    assert {job.id for job in store.jobs(10)} == {first.id, later[1], waiting.id}


def test_a_store_bound_that_leaves_no_room_for_answers_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"TOPTRAJ_MAX_JOBS = 3 leaves no room .* set it above 5"):
        Settings(preload_robots=False, data_dir=tmp_path, max_jobs=3, job_queue=3, job_workers=2)


def test_a_batch_without_a_budget_gets_the_default_within_the_servers_maximum(tmp_path):
    settings = Settings(preload_robots=False, data_dir=tmp_path, job_budget_s=100.0, job_max_budget_s=50.0)
    with TestClient(create_app(settings)) as client:
        response = client.post("/v1/batches", json={"requests": [QUICK]})
        assert response.status_code == 202, response.text
        assert client.get(f"/v1/jobs/{response.json()['id']}").json()["budget_s"] == 50.0


def test_a_batch_out_of_budget_keeps_every_answer_it_has(client):
    """A batch of six-joint collocations (each runs about a second past its line's deadline in
    an SLSQP step) under a budget that ends inside one: the lines stop before the job's budget
    (a reserve kept from them), so the job is done with every answer, the lines it did not
    finish 504s, rather than killed past its budget with all of them."""
    free = {"robot": "ur5", "path": {"kind": "free", "start": [0.0, -1.2, 1.0, 0.0, 0.6, 0.0], "goal": [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]},
            "timing": {"method": "collocation", "grid_points": 100}}
    requests = [QUICK, *({**free, "output": {"dt": 0.01 + 0.001 * k}} for k in range(12)), QUICK]
    response = client.post("/v1/batches", json={"requests": requests, "budget_s": 6.0})
    assert response.status_code == 202, response.text
    job = _wait(client, response.json()["id"])
    assert job["status"] == "done", job["error"]
    results = job["result"]["results"]
    assert [row["line"] for row in results] == list(range(1, 15))
    assert results[0]["status"] == 200 and results[0]["body"]["duration"] > 0
    assert results[-1]["status"] == 504  # the job's budget did not reach it
    assert {row["status"] for row in results[1:-1]} <= {200, 504}


def test_an_answer_larger_than_the_job_store_keeps_fails_the_job_saying_what_fits(tmp_path):
    """A job store of 3 MB under a response cap of 20 MB: a job answering 4 MB of samples was
    pruned as soon as written (404 a second later). The job's answer is held to half the store:
    the job fails with the 422 naming the output.dt that fits, and following it is done."""
    settings = Settings(preload_robots=False, data_dir=tmp_path, job_workers=1, max_job_store_bytes=3_000_000)
    fine = {**QUICK, "output": {"dt": 0.0001}}
    with TestClient(create_app(settings)) as client:
        response = client.post("/v1/jobs", json={"trajectory": fine})
        if response.status_code == 202:
            job = _wait(client, response.json()["id"])
            assert job["status"] == "failed", job["status"]
            problem = job["error"]
        else:
            problem = response.json()
        assert problem["status"] == 422 and "output.dt" in problem["detail"], problem
        smallest = float(re.search(r"output\.dt >= ([\d.e-]+)", problem["detail"]).group(1))
        done = _wait(client, _submit(client, {"trajectory": {**QUICK, "output": {"dt": smallest}}}))
        assert done["status"] == "done", done["error"]
        assert client.get(f"/v1/jobs/{done['id']}").status_code == 200
