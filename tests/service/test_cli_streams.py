"""The console script on what is not a plain file or a plain run: a batch's requests from a pipe
or its output to a device (refused: a batch reads its requests twice and resumes from its
output), a request too large to be one, standard output that cannot be written, Ctrl-C, an
output page that cannot be written (said before planning), a port out of range, and Ray
started apart from a cluster on this machine."""

from __future__ import annotations

import json
import os
import sys
import types

import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj.service import commands
from toptraj.service.cli import main

REQUEST = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}}


def _problem(capsys) -> dict:
    return json.loads(capsys.readouterr().err.strip().splitlines()[-1])


def test_a_batch_reads_a_regular_file_and_writes_one(tmp_path, capsys):
    requests = tmp_path / "in.jsonl"
    requests.write_text(json.dumps(REQUEST) + "\n")
    pipe = tmp_path / "pipe.jsonl"
    os.mkfifo(pipe)  # a reader would block on it, or read it once and find nothing left
    for source in ("-", str(pipe)):
        assert main(["batch", source, "-o", str(tmp_path / "out.jsonl")]) == 2
        detail = _problem(capsys)["detail"]
        assert "is not a regular file" in detail and "write them to a file first" in detail
    for output in ("-", str(pipe), "/dev/null", str(tmp_path)):  # /dev/stdout: a file under pytest's capture
        assert main(["batch", str(requests), "-o", output]) == 2
        assert "give a file's path (e.g. -o results.jsonl)" in _problem(capsys)["detail"]
    assert not (tmp_path / "out.jsonl").exists() and not (tmp_path / "-").exists()


def test_a_request_larger_than_any_is_refused_unread(tmp_path, capsys):
    huge = tmp_path / "huge.json"
    with open(huge, "wb") as handle:
        handle.truncate(3_000_000_000)  # sparse: 3 GB read whole took 47 s and 6 GB of memory
    assert main(["plan", str(huge)]) == 2
    assert "holds more than 2,000,000 bytes" in _problem(capsys)["detail"]


def test_standard_output_that_cannot_be_written_is_said(tmp_path, monkeypatch, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps(REQUEST))

    class Full:
        def write(self, data):
            raise OSError(28, "No space left on device")

        def flush(self):
            pass

    monkeypatch.setattr(sys, "stdout", types.SimpleNamespace(buffer=Full()))
    assert main(["plan", str(request)]) == 2
    assert "No space left on device" in _problem(capsys)["detail"]
    monkeypatch.setattr(sys, "stdout", None)  # closed (>&-)
    assert main(["plan", str(request)]) == 2
    assert "standard output is closed" in _problem(capsys)["detail"]


def test_ctrl_c_ends_a_one_shot_command_with_130_and_no_traceback(tmp_path, monkeypatch, capsys):
    def interrupted(source):
        raise KeyboardInterrupt

    monkeypatch.setattr(commands, "plan", interrupted)
    assert main(["plan", "request.json"]) == 130
    assert capsys.readouterr().err == "toptraj plan: interrupted\n"


def test_a_page_that_cannot_be_written_is_said_before_planning(tmp_path, monkeypatch, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps(REQUEST))
    monkeypatch.setattr(commands, "_run", lambda *args, **kwargs: pytest.fail("planned before the output was checked"))
    assert main(["plot", str(request), "-o", str(tmp_path / "missing" / "page.html")]) == 2
    assert "does not exist" in _problem(capsys)["detail"]
    assert main(["plot", str(request), "-o", str(tmp_path)]) == 2
    assert "is a directory" in _problem(capsys)["detail"]


@pytest.mark.parametrize("port", ["70000", "0", "-5"])
def test_a_port_out_of_range_is_refused(port, capsys):
    assert main(["serve", "--port", port]) == 2
    assert "--port must be a port number from 1 to 65535" in capsys.readouterr().err


class _FakeRay(types.ModuleType):
    """``ray`` as far as ``RayPool`` starts it: ``init`` recorded, or raising ``failure``."""

    def __init__(self, failure: Exception | None = None):
        super().__init__("ray")
        self.calls: list[dict] = []
        self.failure = failure

    def is_initialized(self):
        return False

    def init(self, **kwargs):
        self.calls.append(kwargs)
        if self.failure is not None:
            raise self.failure

    def remote(self, **options):
        return lambda function: function

    def put(self, value):
        return value

    def available_resources(self):
        return {"CPU": 2.0}


def test_a_local_ray_is_its_own_and_ray_client_without_its_packages_is_said(monkeypatch):
    from toptraj.service.batches import ray_pool

    fake = _FakeRay()
    monkeypatch.setitem(sys.modules, "ray", fake)
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    ray_pool.RayPool(None, 2)
    # a cluster started on this machine (ray start --head) is not joined: num_cpus then fails
    assert fake.calls[0]["address"] == "local" and fake.calls[0]["num_cpus"] == 2
    fake = _FakeRay(ValueError("Ray Client requires pip package `ray[client]`."))
    monkeypatch.setitem(sys.modules, "ray", fake)
    monkeypatch.setattr(ray_pool, "check_reachable", lambda address: None)
    with pytest.raises(ray_pool.RayClientMissing, match=r"pip install 'ray\[client\]'"):
        ray_pool.RayPool("ray://head:10001", None)


def test_an_empty_batch_says_it_holds_no_line(tmp_path, capsys):
    requests = tmp_path / "empty.jsonl"
    requests.write_text("")
    assert main(["batch", str(requests), "-o", str(tmp_path / "out.jsonl")]) == 0
    assert "empty.jsonl holds no line: give a file of one request body per line" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["plan", "compare"])
def test_a_closed_standard_output_ends_with_2_and_no_traceback(tmp_path, command):
    import subprocess

    request = tmp_path / "request.json"
    request.write_text(json.dumps(REQUEST))
    ended = subprocess.run(
        [sys.executable, "-m", "toptraj.service.cli", command, str(request)], stdin=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True, preexec_fn=lambda: os.close(1), timeout=120,  # as the shell's >&-
    )
    assert ended.returncode == 2, ended.stderr
    assert "Traceback" not in ended.stderr and "standard output is closed" in ended.stderr


def test_settings_that_cannot_serve_are_refused_before_any_server_process(monkeypatch, capsys):
    """Refused in each server process, they would be started again forever by uvicorn's
    supervisor: ``serve`` says so once and ends."""
    monkeypatch.setenv("TOPTRAJ_MAX_JOBS", "50")
    assert main(["serve", "--port", "8555", "--workers", "2"]) == 2
    assert "TOPTRAJ_MAX_JOBS = 50 leaves no room for an ended job's answer" in capsys.readouterr().err
