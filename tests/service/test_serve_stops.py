"""``toptraj serve --workers 2`` stopped by SIGTERM at any moment: just started, while its
processes are still starting (importing, warming up, the fork server importing the solver
stacks), and warm with a job running: every process it started, and every process those
started, is gone within 5 s (``toptraj.service.stopping``)."""

from __future__ import annotations

import http.client
import json
import os
import signal
import subprocess
import sys
import threading
import time
import uuid

import psutil
import pytest

from tests.live_server import _free_port
from tests.paths import ROOT
from tests.service.test_jobs import SLOW
from toptraj.service.jobs.store import JobStore
from toptraj.service.stopping import descendants

#: Seconds within which every process must be gone.
GONE_S = 5.0


def _describe(process: psutil.Process) -> str:
    try:
        return f"{process.pid} (parent {process.ppid()}): {' '.join(process.cmdline())[-80:]}"
    except psutil.Error:
        return str(process.pid)


class _Server:
    """``python -m toptraj.service.cli serve --workers 2`` whose every process carries a marker in its
    environment (inherited by spawned and forked processes alike), so that a process left
    behind is found even once its parent is gone."""

    def __init__(self, tmp_path, **settings: str):
        self.marker = uuid.uuid4().hex
        self.port = _free_port()
        env = {
            **os.environ,
            "PYTHONPATH": str(ROOT),
            "TOPTRAJ_DATA_DIR": str(tmp_path),
            "TOPTRAJ_STOP_TEST_MARKER": self.marker,
            **settings,
        }
        self.process = subprocess.Popen(
            [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(self.port), "--workers", "2"],
            cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )
        self.log: list[str] = []
        threading.Thread(target=self._read_log, daemon=True).start()

    def _read_log(self) -> None:
        for line in self.process.stderr:
            self.log.append(line)

    def marked(self) -> list[psutil.Process]:
        """The processes alive (not zombies) that carry this server's marker."""
        found = []
        for process in psutil.process_iter():
            try:
                if process.status() != psutil.STATUS_ZOMBIE and process.environ().get("TOPTRAJ_STOP_TEST_MARKER") == self.marker:
                    found.append(process)
            except (psutil.NoSuchProcess, psutil.AccessDenied):
                continue
        return found

    def wait_for_log(self, text: str, count: int, timeout_s: float = 120) -> None:
        give_up = time.monotonic() + timeout_s
        while sum(text in line for line in self.log) < count:
            assert self.process.poll() is None and time.monotonic() < give_up, "".join(self.log[-20:])
            time.sleep(0.02)

    def call(self, method: str, path: str, body: dict | None = None):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        try:
            connection.request(method, path, body=None if body is None else json.dumps(body), headers={"content-type": "application/json"})
            response = connection.getresponse()
            return response.status, json.loads(response.read() or b"null")
        finally:
            connection.close()

    def stop_and_assert_gone(self) -> float:
        """SIGTERM the server; the seconds until none of its processes is left (asserted
        under ``GONE_S``)."""
        tree = self.marked()
        assert tree, "the server has no process"
        self.process.send_signal(signal.SIGTERM)
        started = time.monotonic()
        while (left := self.marked()) and time.monotonic() - started < GONE_S + 5:
            time.sleep(0.05)
        took = time.monotonic() - started
        described = [_describe(process) for process in left]
        for process in left:
            process.kill()
        self.process.wait(timeout=10)
        assert not left and took < GONE_S, f"{len(left)} processes left {took:.1f} s after SIGTERM: {described}"
        return took

    def kill(self) -> None:
        for process in self.marked():
            process.kill()


@pytest.fixture
def server(tmp_path):
    started = _Server(tmp_path)
    yield started
    started.kill()


@pytest.fixture
def light_server(tmp_path):
    """The server without its warm-up (it is up in seconds)."""
    started = _Server(tmp_path, TOPTRAJ_PRELOAD_ROBOTS="false")
    yield started
    started.kill()


def test_sigterm_half_a_second_after_start_leaves_no_process(server):
    time.sleep(0.5)
    server.stop_and_assert_gone()


def test_sigterm_while_the_processes_start_leaves_no_process(server):
    """Both processes are loading the app (imports, then the fork server's imports and the
    warm-up: tens of seconds on a loaded machine, which a stop used to wait for)."""
    server.wait_for_log("Waiting for application startup", count=2)
    time.sleep(0.3)
    server.stop_and_assert_gone()


def test_sigterm_to_a_warm_server_with_a_running_job_leaves_no_process(light_server, tmp_path):
    server = light_server
    server.wait_for_log("Application startup complete", count=2)
    status, job = server.call("POST", "/v1/jobs", {"trajectory": SLOW})
    assert status == 202, job
    give_up = time.monotonic() + 60
    while server.call("GET", f"/v1/jobs/{job['id']}")[1]["status"] != "running":
        assert time.monotonic() < give_up
        time.sleep(0.05)
    workers = [p for p in psutil.Process(server.process.pid).children() if "spawn_main" in " ".join(p.cmdline())]
    assert len(workers) == 2 and any(descendants(worker.pid) for worker in workers)  # the fork server and the job's process
    server.stop_and_assert_gone()
    assert JobStore(tmp_path, 100, 3600.0, 10**8).get(job["id"]).status == "interrupted"  # a graceful stop


def test_descendants_are_read_from_proc():
    child = subprocess.Popen([sys.executable, "-c", "import subprocess, sys, time; subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(30)']); time.sleep(30)"])
    try:
        give_up = time.monotonic() + 10
        while len(descendants(os.getpid())) < 2 and time.monotonic() < give_up:
            time.sleep(0.05)
        found = descendants(os.getpid())
        assert child.pid in found and set(found) == {p.pid for p in psutil.Process().children(recursive=True)}
    finally:
        for pid in [*descendants(child.pid), child.pid]:
            os.kill(pid, signal.SIGKILL)
        child.wait()


def test_a_supervisor_killed_outright_takes_its_processes_with_it(server):
    """SIGKILL runs no handler: the server processes learn it from the kernel (their parent
    gone) and end as on SIGTERM."""
    server.wait_for_log("Waiting for application startup", count=2)
    assert len(server.marked()) >= 3
    server.process.kill()
    started = time.monotonic()
    while server.marked() and time.monotonic() - started < GONE_S + 5:
        time.sleep(0.05)
    assert not server.marked() and time.monotonic() - started < GONE_S
