"""``toptraj batch`` on a Ray cluster of two nodes, both started on this machine with
``ray start`` as on two machines (a head, then a node joining it by address with a resource of
its own): the lines are spread over both nodes and every line is answered once."""

from __future__ import annotations

import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

import psutil
import pytest

from tests.paths import ROOT

pytest.importorskip("ray")  # the "ray" extra, which make test installs

#: Seconds a ``ray start`` may take on a busy machine.
START_S = 180


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _end_processes_of(temp_dir: str) -> None:
    """End the cluster's processes, and theirs: those whose command line names its temporary
    directory (a ``ray stop`` would end every Ray of the machine)."""
    ours = [p for p in psutil.process_iter(["cmdline"]) if p.pid != os.getpid() and any(temp_dir in part for part in p.info["cmdline"] or [])]
    everyone = set(ours)
    for process in ours:
        try:
            everyone.update(process.children(recursive=True))
        except psutil.Error:
            pass
    for process in everyone:
        try:
            process.kill()
        except psutil.Error:
            pass
    psutil.wait_procs(list(everyone), timeout=10)


def _ray_start(arguments: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    command = [str(Path(sys.executable).with_name("ray")), "start", "--num-cpus", "1", "--object-store-memory", str(80 * 1024 * 1024), "--disable-usage-stats", *arguments]
    return subprocess.run(command, env=env, capture_output=True, text=True, timeout=START_S, check=False)


@pytest.fixture
def two_nodes():
    """The address of a Ray cluster of two nodes of one CPU each, the second with the resource
    ``node2``, and the environment to reach it; ended (its processes killed) afterwards. Token
    authentication off: the nodes and the driver share no token file here."""
    temp_dir = tempfile.mkdtemp(prefix="ray-", dir="/tmp")  # short: Ray's socket paths live under it
    env = {**os.environ, "RAY_AUTH_MODE": "disabled", "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    address = f"127.0.0.1:{_free_port()}"
    try:
        head = _ray_start(["--head", "--port", address.rsplit(":", 1)[1], "--include-dashboard", "false", "--temp-dir", temp_dir], env)
        if head.returncode != 0:
            pytest.skip(f"ray cannot start a head node here: {head.stderr[-500:]}")
        second = _ray_start(["--address", address, "--resources", json.dumps({"node2": 1})], env)
        if second.returncode != 0:
            pytest.skip(f"ray cannot start a second node here: {second.stderr[-500:]}")
        yield address, env
    finally:
        _end_processes_of(temp_dir)
        shutil.rmtree(temp_dir, ignore_errors=True)


def test_a_batch_spreads_over_the_nodes_of_a_cluster(two_nodes, tmp_path):
    """``toptraj batch --ray-address HOST:PORT``, as a user runs it (its own process, the
    driver of the cluster's job)."""
    lines = [
        json.dumps({"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.3 + 0.02 * k, 0.2, -0.2, 0.1, 0.2, 0.3]]}})
        for k in range(16)
    ]
    requests, output = tmp_path / "requests.jsonl", tmp_path / "results.jsonl"
    requests.write_text("\n".join(lines) + "\n")
    address, env = two_nodes
    command = [sys.executable, "-m", "toptraj.service.cli", "batch", str(requests), "-o", str(output), "--ray-address", address]
    done = subprocess.run(command, env=env, cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    rows = [json.loads(row) for row in output.read_text().splitlines()]
    assert sorted(row["line"] for row in rows) == list(range(1, 17))  # every line once
    assert {row["status"] for row in rows} == {200}, rows
    spread = re.search(r"16 answered, .*, on 2 Ray nodes \((\d+), (\d+) requests\)", done.stderr)
    assert spread and int(spread[1]) + int(spread[2]) == 16, done.stderr[-2000:]  # both nodes answered
