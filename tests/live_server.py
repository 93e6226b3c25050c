"""A real ``toptraj serve`` in a subprocess, for tests that need a server process of their own:
the CPU time it spends after a 504, ``/health`` answering while another request runs, or
uploads seen by every one of several server processes."""

from __future__ import annotations

import http.client
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parents[1]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class LiveServer:
    """``python -m toptraj.service.cli serve --workers W`` on a free port with ``TOPTRAJ_*`` settings
    ``env``; one server process unless ``workers`` asks for more."""

    def __init__(self, workers: int = 1, **env: str):
        self.port = _free_port()
        self.workers = workers
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])), **env}
        self.process: subprocess.Popen | None = None

    def __enter__(self) -> LiveServer:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(self.port), "--workers", str(self.workers)],
            cwd=ROOT,
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        give_up = time.monotonic() + 120
        while time.monotonic() < give_up:
            if self.process.poll() is not None:
                raise RuntimeError(f"the server exited with code {self.process.returncode}")
            try:
                if self.request("GET", "/health", timeout=2)[0] == 200 and len(self.serving_pids()) == self.workers:
                    return self
            except OSError:
                pass
            time.sleep(0.1)
        raise RuntimeError("the server did not answer /health within 120 s")

    def __exit__(self, *exc) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()

    def request(self, method: str, path: str, body: dict | None = None, timeout: float = 120):
        """(status, headers, body bytes) of one request on a new connection."""
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout)
        try:
            payload = None if body is None else json.dumps(body).encode()
            connection.request(method, path, body=payload, headers={"content-type": "application/json"})
            response = connection.getresponse()
            return response.status, dict(response.getheaders()), response.read()
        finally:
            connection.close()

    def serving_pids(self) -> list[int]:
        """Process ids of the processes answering requests: the server itself when it runs one
        worker, else the worker processes uvicorn spawned."""
        root = psutil.Process(self.process.pid)
        if self.workers == 1:
            return [root.pid]
        return [child.pid for child in root.children() if "spawn_main" in " ".join(child.cmdline())]

    def cpu_seconds(self) -> float:
        """CPU time (user + system) used so far by the server and every process under it,
        including the children they have already reaped."""
        total = 0.0
        root = psutil.Process(self.process.pid)
        for process in [root, *root.children(recursive=True)]:
            try:
                times = process.cpu_times()
            except psutil.NoSuchProcess:
                continue
            total += times.user + times.system + times.children_user + times.children_system
        return total

    def wait_until_idle(self, window_s: float = 0.5, cpu_s: float = 0.05, timeout_s: float = 120) -> None:
        """Return once the server tree used less than ``cpu_s`` CPU seconds over ``window_s``
        (start-up work such as the worker server's imports is over)."""
        give_up = time.monotonic() + timeout_s
        while time.monotonic() < give_up:
            before = self.cpu_seconds()
            time.sleep(window_s)
            if self.cpu_seconds() - before < cpu_s:
                return
        raise RuntimeError(f"the server did not come to rest within {timeout_s} s")
