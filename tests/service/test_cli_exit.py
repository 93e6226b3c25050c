"""The ``toptraj`` program (``toptraj.service.cli.run``): a one-shot command ends as soon as its
output is flushed, skipping the interpreter's teardown of its modules, with its whole answer
written, its exit status and its exit handlers run; ``serve`` and the others end as usual.
Each in a fresh interpreter, as the program runs."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from tests.conftest import UR5_WAYPOINTS
from tests.paths import ROOT

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
#: ``toptraj ARGS`` through ``run``, with witnesses of how the process ended: an exit handler
#: (said as it runs) and a module-level object whose finalizer speaks only if the interpreter
#: tears its modules down.
_PROGRAM = """
import atexit, sys
from toptraj.service import cli

class Witness:
    def __del__(self):
        sys.stderr.write("torn down\\n")

cli.witness = Witness()
atexit.register(lambda: sys.stderr.write("exit handlers ran\\n"))
sys.argv = ["toptraj", *sys.argv[1:]]
cli.run()
"""


def _toptraj(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", _PROGRAM, *args], cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=600)


def test_plan_ends_without_teardown_with_its_whole_answer(tmp_path):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "output": {"dt": 0.001}}))
    done = _toptraj("plan", str(request))
    assert done.returncode == 0, done.stderr[-2000:]
    body = json.loads(done.stdout)  # all of it: 1 ms samples make an answer of hundreds of kB
    assert body["robot"] == "ur5" and len(body["samples"]["t"]) > 1_000
    assert done.stderr.splitlines() == ["exit handlers ran"]


def test_an_error_keeps_its_status_and_its_problem(tmp_path):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "no_such_arm", "path": {"waypoints": UR5_WAYPOINTS}}))
    done = _toptraj("plan", str(request))
    assert done.returncode == 1 and done.stdout == ""
    problem, said = done.stderr.splitlines()
    assert json.loads(problem)["status"] == 404 and said == "exit handlers ran"
    assert _toptraj("plan", str(tmp_path / "missing.json")).returncode == 2


def test_other_commands_end_as_usual():
    done = _toptraj("batch", "--help")
    assert done.returncode == 0 and "JSON Lines" in done.stdout
    assert done.stderr.splitlines() == ["exit handlers ran", "torn down"]
