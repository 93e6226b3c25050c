"""Batches never lose a line: every line of a request file, however hostile, gets exactly one
result line carrying its line number; identical requests are computed once; an interrupted or
failed run resumes by line number (``--retry-failed`` plans the 504s and 5xx again); a line's
failure inside planning is that line's result, in ``toptraj batch`` and in ``POST /v1/batches``.

The driver's logic runs here on ``InProcessPool`` (the requests answered in this process by
the workers' own function); one test stops a real local Ray with SIGINT."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import orjson
import psutil
import pytest

import toptraj.service.batches.work as batch_work
from tests.paths import ROOT
from toptraj.planners import Deadline
from toptraj.service.batches import lines as lines_
from toptraj.service.batches import run_batch, runner
from toptraj.service.batches.lines import request_key
from toptraj.service.batches.work import answer, answer_chunk
from toptraj.service.cli import main
from toptraj.service.jobs.work import WorkerSetup, _batch
from toptraj.service.strict_json import MAX_DEPTH, nesting_depth

GOOD = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.4, 0.3, -0.2, 0.1, 0.2, 0.3]]}}
OTHER = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [-0.3, 0.2, 0.2, -0.1, 0.1, 0.2]]}}


class _Done:
    """A finished task of ``InProcessPool``."""

    def __init__(self, answers):
        self.answers = answers


class InProcessPool:
    """``RayPool``'s interface, each chunk answered at once in this process by
    ``work.answer_chunk`` (what a Ray worker runs); ``after_submit(pool)`` runs after each."""

    cpus = 1

    def __init__(self, after_submit=None):
        self.chunks: list[list[tuple[str, str]]] = []
        self.after_submit = after_submit
        self.closed = False

    def share(self, uploads):
        self.uploads = uploads

    def submit(self, chunk, budget_s):
        self.chunks.append(list(chunk))
        done = _Done(answer_chunk(chunk, self.uploads, budget_s))
        if self.after_submit:
            self.after_submit(self)
        return done

    def wait(self, handles, timeout_s):
        return list(handles), []

    def result(self, handle):
        return handle.answers

    def cancel(self, handles):
        pass

    def close(self):
        self.closed = True

    @property
    def keys(self) -> list[str]:
        return [key for chunk in self.chunks for key, _ in chunk]


def _rows(path: Path) -> list[dict]:
    return [orjson.loads(raw) for raw in path.read_bytes().splitlines()]


def _by_line(path: Path) -> dict[int, dict]:
    rows = _rows(path)
    numbers = [row["line"] for row in rows]
    assert len(numbers) == len(set(numbers)), f"a line answered twice: {sorted(numbers)}"
    return {row["line"]: row for row in rows}


def _hostile_file(path: Path, monkeypatch) -> dict[int, int]:
    """A request file of every kind of line, and the status each line must get."""
    monkeypatch.setattr(lines_, "MAX_LINE_BYTES", 20_000)
    deep = "[" * 1300 + "]" * 1300  # 2.6 KB: RecursionError in a recursive parser
    lines: list[tuple[bytes, int]] = [
        (b"\xef\xbb\xbf" + json.dumps(GOOD).encode(), 200),  # a byte order mark before the first line
        (b"not json", 422),  # as POST /v1/trajectories answers a body that is no JSON
        (deep.encode(), 400),
        (b'{"robot": "ur5", "path": ' + b"[" * 60 + b"]" * 60 + b"}", 400),
        (b"", 422),
        (b"   \t ", 422),
        (b"42", 422),
        (b"[1, 2]", 422),
        (b'"a string"', 422),
        (b"null", 422),
        (json.dumps(GOOD, indent=None, separators=(", ", ": ")).encode(), 200),  # the same request again
        (b'{"robot": "\xff\xfe"}', 422),  # not UTF-8
        (b'{"robot": "ur5", "path": {"waypoints": "no"}}', 422),
        (json.dumps({**GOOD, "robot": "nope"}).encode(), 404),
        (b'{"robot": "' + b"x" * 30_000 + b'"}', 413),
        (json.dumps(OTHER).encode(), 200),
        (json.dumps(GOOD).encode(), 200),  # and again
        (b'{"robot": "ur5", "path": {"waypoints": [[0,0,0,0,0,0]]}', 422),  # cut short
        (b"{" + b'"a": {' * 40 + b"}" * 40 + b"}", 400),
        (b'{"robot": "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[", "path": 1}', 422),  # brackets in a string are no nesting
        (b'{"robot": "\\ud800"}', 422),  # a lone surrogate: JSON text, but no Unicode
        (b'{"robot": "ur5", "grid": 123456789012345678901234567890}', 422),  # an integer beyond 64 bits
        (json.dumps(OTHER).encode(), 200),  # and the lines after them are planned
        (b'{"robot": "ur5", "grid": ' + b"9" * 5000 + b"}", 422),  # more digits than Python converts
        (json.dumps({**GOOD, "payload": None}).encode(), 200),
        (b'{"robot": "ur5", "path": {"waypoints": [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.4, 0.3, -0.2, 0.1, 0.2, 0.3]]}, "payload": 1e400}', 422),
    ]
    path.write_bytes(b"\n".join(raw for raw, _ in lines) + b"\n")
    return {number: status for number, (_, status) in enumerate(lines, start=1)}


def test_every_line_gets_exactly_one_result_line_with_its_number(tmp_path, monkeypatch):
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    expected = _hostile_file(requests, monkeypatch)
    pool = InProcessPool()
    report = run_batch(requests, output, pool=lambda: pool)
    rows = _by_line(output)
    assert {number: row["status"] for number, row in rows.items()} == expected
    assert (report.total, report.skipped, report.planned, report.interrupted) == (len(expected), 0, len(expected), False)
    # identical requests (whatever their formatting) are computed once, each line written
    assert rows[1]["key"] == rows[11]["key"] == rows[17]["key"] == request_key(json.dumps(GOOD))
    assert rows[1]["body"] == rows[11]["body"] == rows[17]["body"] and rows[1]["body"]["duration"] > 0
    assert sorted(pool.keys) == sorted({rows[n]["key"] for n in (1, 13, 14, 16, 20, 25)}) and pool.closed
    assert rows[23]["key"] == rows[16]["key"] and rows[23]["body"] == rows[16]["body"]
    # each refusal says what and where
    assert rows[3]["body"]["title"] == "Too deeply nested" and "line 3" in rows[3]["body"]["detail"]
    assert rows[15]["body"]["title"] == "Line too long" and "30013 bytes" in rows[15]["body"]["detail"]
    assert "JSON number" in rows[7]["body"]["detail"] and "JSON array" in rows[8]["body"]["detail"]
    assert "JSON string" in rows[9]["body"]["detail"] and "JSON null" in rows[10]["body"]["detail"]
    assert "UTF-8" in rows[12]["body"]["detail"]
    assert "no lone" in rows[21]["body"]["detail"] and "64 bits" in rows[22]["body"]["detail"]
    assert rows[24]["body"]["detail"] == "line 24: a number has more than 4300 digits; a request's numbers (joint values, limits, settings) need a few"
    # a number beyond a double's range is no infinity (which would read as null, one key with line 25's)
    assert rows[26]["body"]["detail"].startswith("line 26: the number 1e400 is beyond the range of a double") and rows[25]["key"] != rows[26]["key"]
    assert all(row["body"]["status"] == row["status"] for row in rows.values() if row["status"] != 200)
    assert all(len(row["body"].get("detail", "")) < 1000 for row in rows.values())
    # a second run has nothing left to do
    assert run_batch(requests, output, pool=InProcessPool).planned == 0


def test_the_nesting_depth_is_counted_without_recursion():
    assert nesting_depth(b'{"a": [1, {"b": [[2]]}], "c": "]]]][[[[{{{{"}') == 5
    assert nesting_depth(b'{"a": "\\"[[[[", "b": [[]]}') == 3  # an escaped quote does not end the string
    assert nesting_depth(b"42") == 0 and nesting_depth(b"") == 0
    started = time.perf_counter()
    assert nesting_depth(b"[" * 1_000_000 + b"]" * 1_000_000) == 1_000_000
    assert time.perf_counter() - started < 2.0
    assert MAX_DEPTH >= nesting_depth(json.dumps({**GOOD, "limits": {"max_velocity": [1.0] * 6}}).encode())


def test_a_stopped_run_keeps_what_finished_and_resumes_by_line_number(tmp_path):
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    bodies = [GOOD, OTHER, GOOD, {**OTHER, "robot": "nope"}, OTHER, {**GOOD, "output": {"dt": 0.02}}, GOOD, {**GOOD, "output": {"dt": 0.03}}]
    bodies += [{**GOOD, "output": {"dt": 0.01 + 0.001 * k}} for k in range(8)]
    requests.write_text("".join(json.dumps(body) + "\n" for body in bodies))
    stop = threading.Event()
    first = run_batch(requests, output, stop=stop, pool=lambda: InProcessPool(lambda pool: len(pool.chunks) == 2 and stop.set()))
    assert first.interrupted and 0 < first.planned < len(bodies)
    partial = _by_line(output)
    assert len(partial) == first.planned
    # the run after it was killed while writing a line
    output.write_bytes(output.read_bytes() + b'{"line": 16, "key": "ab')
    pool = InProcessPool()
    second = run_batch(requests, output, pool=lambda: pool)
    assert (second.skipped, second.planned, second.interrupted) == (first.planned, len(bodies) - first.planned, False)
    rows = _by_line(output)
    assert sorted(rows) == list(range(1, len(bodies) + 1))
    assert all(rows[n]["key"] == request_key(json.dumps(body)) for n, body in enumerate(bodies, start=1))
    assert not set(pool.keys) & {row["key"] for row in partial.values()}  # nothing planned twice


def test_a_stop_before_the_planning_starts_no_pool(tmp_path):
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text("not json\n" + json.dumps(GOOD) + "\n")
    stop = threading.Event()
    stop.set()
    report = run_batch(requests, output, stop=stop, pool=lambda: pytest.fail("no pool may start"))
    assert report.interrupted and report.planned == 0
    assert sorted(_by_line(output)) == []
    assert run_batch(requests, output, pool=InProcessPool).planned == 2


def test_retry_failed_plans_the_504s_and_5xx_again_within_the_given_budget(tmp_path):
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text(json.dumps(GOOD) + "\n" + json.dumps(OTHER) + "\n" + json.dumps({**GOOD, "robot": "nope"}) + "\n")
    run_batch(requests, output, budget_s=1e-9, pool=InProcessPool)  # a budget nothing fits in
    assert {n: row["status"] for n, row in _by_line(output).items()} == {1: 504, 2: 504, 3: 404}
    assert "budget" in _by_line(output)[1]["body"]["detail"]
    rows = output.read_bytes().splitlines(keepends=True)
    output.write_bytes(rows[0] + rows[2] + rows[1].replace(b'"status":504', b'"status":503'))
    assert run_batch(requests, output, pool=InProcessPool).planned == 0  # a resume keeps them
    pool = InProcessPool()
    report = run_batch(requests, output, retry_failed=True, pool=lambda: pool)
    assert (report.skipped, report.planned) == (1, 2) and len(pool.keys) == 2
    assert {n: row["status"] for n, row in _by_line(output).items()} == {1: 200, 2: 200, 3: 404}
    assert not list(tmp_path.glob("*.resuming"))


class _Hanging(_Done):
    """A task whose worker never ends (a solver step that cannot check its deadline)."""


class HangingPool(InProcessPool):
    """``InProcessPool`` whose tasks holding ``OTHER`` never end until cancelled."""

    def __init__(self):
        super().__init__()
        self.cancelled: list = []

    def submit(self, chunk, budget_s):
        if any(text == json.dumps(OTHER) for _, text in chunk):
            self.chunks.append(list(chunk))
            return _Hanging(None)
        return super().submit(chunk, budget_s)

    def wait(self, handles, timeout_s):
        ready = [h for h in handles if not isinstance(h, _Hanging)]
        if not ready:
            time.sleep(timeout_s)
        return ready, [h for h in handles if isinstance(h, _Hanging)]

    def cancel(self, handles):
        self.cancelled += handles


def test_a_task_past_its_budget_is_killed_and_its_lines_are_504s(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "CHUNK", 1)
    monkeypatch.setattr(runner, "TASK_SLACK_S", 0.5)
    monkeypatch.setattr(runner, "STARTUP_S", 0.0)  # the workers' start is another test's
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text(json.dumps(OTHER) + "\n" + json.dumps(GOOD) + "\n" + json.dumps(OTHER) + "\n")
    answer(json.dumps(GOOD), 20.0)  # the robot loaded and the kernels compiled before the 0.5 s budget
    pool = HangingPool()
    started = time.monotonic()
    report = run_batch(requests, output, budget_s=0.5, pool=lambda: pool)
    assert time.monotonic() - started < 0.5 + 0.5 + 1.0  # its budget, the slack, the polls
    assert {n: row["status"] for n, row in _by_line(output).items()} == {1: 504, 2: 200, 3: 504}
    assert "--retry-failed" in _by_line(output)[1]["body"]["detail"]
    assert len(pool.cancelled) == 1 and not report.interrupted


@pytest.mark.parametrize("budget", ["0", "-1", "nan", "1e9"])
def test_the_budget_option_is_checked(tmp_path, capsys, budget):
    (tmp_path / "in.jsonl").write_text(json.dumps(GOOD) + "\n")
    assert main(["batch", str(tmp_path / "in.jsonl"), "-o", str(tmp_path / "out.jsonl"), "--budget", budget]) == 2
    assert "--budget must be in (0, 3600] s" in capsys.readouterr().err


def test_batch_without_ray_names_the_extra_to_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray raises ImportError
    (tmp_path / "in.jsonl").write_text(json.dumps(GOOD) + "\nnot json\n")
    assert main(["batch", str(tmp_path / "in.jsonl"), "-o", str(tmp_path / "out.jsonl")]) == 2
    err = capsys.readouterr().err
    assert "pip install 'toptraj[ray]'" in err and "Traceback" not in err
    problem = json.loads(err.strip().splitlines()[-1])
    assert problem["status"] == 400 and problem["title"] == "Ray is not installed"


@pytest.mark.parametrize("address, words", [("127.0.0.1:1", "nothing accepts a connection at --ray-address 127.0.0.1:1"), ("nohost", "is no cluster address")])
def test_batch_on_a_cluster_address_where_nothing_listens_says_so_at_once(tmp_path, capsys, address, words):
    """Ray retries such an address for minutes, deaf to Ctrl-C: the address is tried first."""
    pytest.importorskip("ray")
    import ray

    if ray.is_initialized():
        pytest.skip("a Ray of this process is running")
    (tmp_path / "in.jsonl").write_text(json.dumps(GOOD) + "\n")
    started = time.monotonic()
    assert main(["batch", str(tmp_path / "in.jsonl"), "-o", str(tmp_path / "out.jsonl"), "--ray-address", address]) == 2
    assert time.monotonic() - started < 30.0
    problem = json.loads(capsys.readouterr().err.strip().splitlines()[-1])
    assert problem["title"] == "Ray cluster unreachable" and words in problem["detail"], problem
    assert not ray.is_initialized()
    assert not (tmp_path / "out.jsonl").exists()  # no empty output to mistake for one


@pytest.mark.parametrize("reply", [b"HTTP/1.1 400 Bad Request\r\n\r\n", b"SSH-2.0-OpenSSH_9.6\r\n", None])
def test_batch_on_an_address_where_another_server_listens_says_so_at_once(tmp_path, capsys, monkeypatch, reply):
    """A web server, an SSH server, or one that never answers at --ray-address: Ray would retry
    it for minutes, deaf to Ctrl-C; the HTTP/2 opening a Ray head answers is tried first."""
    pytest.importorskip("ray")
    import socket

    import ray

    from toptraj.service.batches import ray_pool

    if ray.is_initialized():
        pytest.skip("a Ray of this process is running")
    monkeypatch.setattr(ray_pool, "CONNECT_S", 1.0)
    listener = socket.create_server(("127.0.0.1", 0))
    held = []

    def serve():
        connection, _ = listener.accept()
        held.append(connection)
        if reply is not None:
            connection.sendall(reply)

    threading.Thread(target=serve, daemon=True).start()
    address = f"127.0.0.1:{listener.getsockname()[1]}"
    (tmp_path / "in.jsonl").write_text(json.dumps(GOOD) + "\n")
    started = time.monotonic()
    try:
        assert main(["batch", str(tmp_path / "in.jsonl"), "-o", str(tmp_path / "out.jsonl"), "--ray-address", address]) == 2
    finally:
        listener.close()
        for connection in held:
            connection.close()
    assert time.monotonic() - started < 10.0
    problem = json.loads(capsys.readouterr().err.strip().splitlines()[-1])
    assert problem["title"] == "Ray cluster unreachable", problem
    assert f"--ray-address {address} is no Ray cluster" in problem["detail"] and "6379" in problem["detail"], problem
    assert not ray.is_initialized() and not (tmp_path / "out.jsonl").exists()


def _fails_on_panda(monkeypatch):
    planned = batch_work.plan_request

    def plan(request, *args, **kwargs):
        if request.robot == "panda":
            raise RuntimeError("ruckig: the input is out of range")
        return planned(request, *args, **kwargs)

    monkeypatch.setattr(batch_work, "plan_request", plan)


def test_a_line_failing_inside_planning_is_that_lines_500(monkeypatch):
    _fails_on_panda(monkeypatch)
    status, body = answer(json.dumps({"robot": "panda", "path": {"waypoints": [[0.0] * 7, [0.1] * 7]}}), 5.0)
    problem = orjson.loads(body)
    assert status == 500 == problem["status"] and "RuntimeError" in problem["detail"]
    assert "out of range" not in problem["detail"]  # the solver's text is logged, not answered
    assert answer(json.dumps(GOOD), 5.0)[0] == 200


def _setup(tmp_path) -> WorkerSetup:
    return WorkerSetup(str(tmp_path), 10, 1_000_000, 4, 50_000_000)


def test_a_batch_job_answers_every_good_line_when_one_fails_inside_planning(tmp_path, monkeypatch):
    _fails_on_panda(monkeypatch)
    bad = {"robot": "panda", "path": {"waypoints": [[0.0] * 7, [0.1] * 7]}}
    request = orjson.dumps({"requests": [GOOD, bad, OTHER, {**GOOD, "robot": "nope"}]}).decode()
    results = orjson.loads(_batch(request, Deadline(60.0), _setup(tmp_path)))["results"]
    assert [(row["line"], row["status"]) for row in results] == [(1, 200), (2, 500), (3, 200), (4, 404)]
    assert results[0]["body"]["duration"] > 0 and results[1]["body"]["title"] == "Internal error"


def test_a_batch_job_out_of_budget_answers_each_line_it_did_not_reach_with_a_504(tmp_path):
    request = orjson.dumps({"requests": [GOOD, OTHER]}).decode()
    deadline = Deadline(0.01)
    time.sleep(0.02)
    results = orjson.loads(_batch(request, deadline, _setup(tmp_path)))["results"]
    assert [(row["line"], row["status"]) for row in results] == [(1, 504), (2, 504)]
    assert "budget_s" in results[0]["body"]["detail"]


def test_sigint_stops_a_ray_batch_within_seconds_and_leaves_no_process(tmp_path):
    """Two Ctrl-C (SIGINT to the driver's process group): it stops within seconds with status
    130, says how to resume, keeps whole result lines only (a worker interrupted writes no
    error line), and every process it started is gone."""
    pytest.importorskip("ray")
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text("".join(json.dumps({**GOOD, "output": {"dt": 0.001 + 1e-6 * k}}) + "\n" for k in range(3000)))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    driver = subprocess.Popen(
        [sys.executable, "-m", "toptraj.service.cli", "batch", str(requests), "-o", str(output), "--workers", "2"],
        stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path, start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 60
        while not (output.exists() and output.stat().st_size > 0):
            assert driver.poll() is None and time.monotonic() < deadline, "no result line came"
            time.sleep(0.1)
        children = psutil.Process(driver.pid).children(recursive=True)
        assert any("raylet" in child.name() for child in children)
        os.killpg(driver.pid, signal.SIGINT)  # as Ctrl-C in a terminal: to the driver and every process of its group
        time.sleep(0.3)
        os.killpg(driver.pid, signal.SIGINT)  # a second one changes nothing
        started = time.monotonic()
        err = driver.communicate(timeout=15)[1]
        assert time.monotonic() - started < 10
    finally:
        if driver.poll() is None:
            driver.kill()
    assert driver.returncode == 130, err[-2000:]
    assert f"resume with: toptraj batch {requests} -o {output} --workers 2" in err and "Traceback" not in err
    gone = time.monotonic() + 5
    while [c for c in children if c.is_running() and c.status() != psutil.STATUS_ZOMBIE] and time.monotonic() < gone:
        time.sleep(0.1)
    assert not [c.name() for c in children if c.is_running() and c.status() != psutil.STATUS_ZOMBIE]
    assert output.read_bytes().endswith(b"\n")
    rows = _by_line(output)
    assert 0 < len(rows) < 3000 and all(row["status"] == 200 for row in rows.values())


def test_two_lines_too_long_of_one_length_have_keys_of_their_own(tmp_path, monkeypatch):
    """A line over the cap is keyed by the SHA-256 of its bytes, hashed as they are skipped (not
    of its length, which two different lines may share)."""
    monkeypatch.setattr(lines_, "MAX_LINE_BYTES", 1_000)
    path = tmp_path / "long.jsonl"
    first, second = b'{"robot": "' + b"x" * 5_000 + b'"}', b'{"robot": "' + b"y" * 5_000 + b'"}'
    path.write_bytes(first + b"\n" + second + b"\n")
    read = list(lines_.read_requests(path))
    assert [line.problem[0] for line in read] == [413, 413]
    assert read[0].key != read[1].key


def test_a_line_fixed_after_its_4xx_is_planned_again_and_answered_once(tmp_path):
    """A resumed run plans the lines whose request changed since their result (the result's key
    is no longer the line's), in place of the old result, and leaves the others as they are."""
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text(json.dumps(GOOD) + "\nnot json\n" + json.dumps(OTHER) + "\n")
    run_batch(requests, output, pool=InProcessPool)
    assert {n: row["status"] for n, row in _by_line(output).items()} == {1: 200, 2: 422, 3: 200}
    requests.write_text(json.dumps(GOOD) + "\n" + json.dumps({**OTHER, "output": {"dt": 0.02}}) + "\n" + json.dumps(OTHER) + "\n")
    pool = InProcessPool()
    report = run_batch(requests, output, pool=lambda: pool)
    assert (report.skipped, report.planned) == (2, 1)
    rows = _by_line(output)  # one result a line
    assert {n: row["status"] for n, row in rows.items()} == {1: 200, 2: 200, 3: 200}
    assert rows[2]["key"] == request_key(json.dumps({**OTHER, "output": {"dt": 0.02}}))
    assert len(pool.chunks) == 1 and [key for key, _ in pool.chunks[0]] == [rows[2]["key"]]
    assert run_batch(requests, output, pool=InProcessPool).planned == 0


def test_the_driver_holds_only_the_lines_in_flight(tmp_path):
    """A file of 60 requests of 200 kB each (12 MB): the driver reads them as the tasks need
    them, so its memory at peak holds a few chunks of them, not the file (it gathered every
    line's text before planning: 488 MB for 200 lines of 1 MB)."""
    import tracemalloc

    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    with open(requests, "w") as handle:
        for k in range(60):  # each its own request (a 422: an unknown field), answered at once
            handle.write(json.dumps({**GOOD, "note": "x" * (200_000 + k)}) + "\n")
    class Forgetful(InProcessPool):  # keeps no chunk (InProcessPool keeps them all for its keys)
        def submit(self, chunk, budget_s):
            return _Done(answer_chunk(chunk, self.uploads, budget_s))

    tracemalloc.start()
    try:
        report = run_batch(requests, output, pool=Forgetful)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert report.planned == 60 and {row["status"] for row in _by_line(output).values()} == {422}
    assert peak < 9_000_000, f"{peak / 1e6:.1f} MB at peak"  # the file is 12 MB


def test_a_run_s_first_tasks_get_time_for_the_workers_to_start(tmp_path, monkeypatch):
    """Before any task has answered, a task is not killed at its lines' budgets plus the slack:
    Ray's workers may still be starting (ten seconds and more), which is no line's planning
    (a --budget 0.5 made every line a 504 that way). Here the workers take 1 s to answer."""
    monkeypatch.setattr(runner, "TASK_SLACK_S", 0.2)
    monkeypatch.setattr(runner, "STARTUP_S", 5.0)

    class Slow(InProcessPool):
        def __init__(self):
            super().__init__()
            self.started = time.monotonic()

        def wait(self, handles, timeout_s):
            if time.monotonic() - self.started < 1.0:  # the workers starting
                time.sleep(min(timeout_s, 0.05))
                return [], list(handles)
            return list(handles), []

    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text(json.dumps(GOOD) + "\n" + json.dumps(OTHER) + "\n")
    run_batch(requests, output, budget_s=0.2, pool=Slow)
    assert {n: row["status"] for n, row in _by_line(output).items()} == {1: 200, 2: 200}


def test_a_batch_job_on_a_cluster_address_where_nothing_listens_fails_at_once(tmp_path):
    """The server's TOPTRAJ_RAY_ADDRESS is tried first: a 503 naming it within seconds, not a
    job spending its whole budget on Ray's retries."""
    pytest.importorskip("ray")
    import ray

    from toptraj.service.batches.ray_pool import RayUnreachable
    from toptraj.service.problems import status_of

    if ray.is_initialized():
        pytest.skip("a Ray of this process is running")
    setup = WorkerSetup(str(tmp_path), 10, 1_000_000, 4, 50_000_000, ray_address="127.0.0.1:1")
    started = time.monotonic()
    with pytest.raises(RayUnreachable) as refused:
        _batch(orjson.dumps({"requests": [GOOD]}).decode(), Deadline(60.0), setup)
    assert time.monotonic() - started < 30.0 and status_of(refused.value) == 503
    assert "nothing accepts a connection at TOPTRAJ_RAY_ADDRESS 127.0.0.1:1" in refused.value.detail
    assert refused.value.detail.endswith("set TOPTRAJ_RAY_ADDRESS=local for a Ray of the job's own")


def test_a_first_task_that_hangs_is_still_killed_after_the_workers_start_allowance(tmp_path, monkeypatch):
    """The start allowance is bounded: a task of the first wave that never answers is killed
    at its lines' budgets plus the slack plus ``STARTUP_S``, and its lines are 504s."""
    monkeypatch.setattr(runner, "CHUNK", 1)
    monkeypatch.setattr(runner, "TASK_SLACK_S", 0.2)
    monkeypatch.setattr(runner, "STARTUP_S", 0.8)
    requests, output = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    requests.write_text(json.dumps(OTHER) + "\n" + json.dumps(GOOD) + "\n")
    started = time.monotonic()
    run_batch(requests, output, budget_s=0.2, pool=HangingPool)
    assert 0.2 + 0.2 + 0.8 <= time.monotonic() - started < 0.2 + 0.2 + 0.8 + 1.0
    assert {n: row["status"] for n, row in _by_line(output).items()} == {1: 504, 2: 200}


def test_an_output_of_another_request_file_is_left_as_it_is(tmp_path):
    """Most results of other requests than the lines hold: the output of another file given by
    mistake, refused whole (planning its lines again would have dropped every result)."""
    first, second, output = tmp_path / "a.jsonl", tmp_path / "b.jsonl", tmp_path / "out.jsonl"
    first.write_text(json.dumps(GOOD) + "\n" + json.dumps(OTHER) + "\n" + json.dumps({**GOOD, "output": {"dt": 0.02}}) + "\n")
    second.write_text("".join(json.dumps({**OTHER, "output": {"dt": 0.01 + 0.001 * k}}) + "\n" for k in range(3)))
    run_batch(first, output, pool=InProcessPool)
    kept = output.read_bytes()
    with pytest.raises(lines_.ForeignOutput, match="3 of its 3 results are of other requests"):
        run_batch(second, output, pool=InProcessPool)
    assert output.read_bytes() == kept


def test_ray_s_own_address_variable_names_the_cluster(tmp_path, capsys, monkeypatch):
    """RAY_ADDRESS set and no --ray-address: that cluster, tried as --ray-address is (a local Ray
    started with it set crashed with a traceback)."""
    pytest.importorskip("ray")
    import ray

    if ray.is_initialized():
        pytest.skip("a Ray of this process is running")
    monkeypatch.setenv("RAY_ADDRESS", "127.0.0.1:1")
    (tmp_path / "in.jsonl").write_text(json.dumps(GOOD) + "\n")
    assert main(["batch", str(tmp_path / "in.jsonl"), "-o", str(tmp_path / "out.jsonl")]) == 2
    problem = json.loads(capsys.readouterr().err.strip().splitlines()[-1])
    assert problem["title"] == "Ray cluster unreachable" and "127.0.0.1:1" in problem["detail"], problem
