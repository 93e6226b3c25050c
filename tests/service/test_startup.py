"""Start-up: ``toptraj plan`` imports only what the chosen method needs; a server whose kernels
are in numba's cache starts without compiling one, without importing the solver stacks it does
not run itself, and saying each step; warm start-up changes no answer. Each in a fresh
interpreter (what is imported is the question); the seconds are in ``benchmarks/startup.py``."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from tests.conftest import UR5_WAYPOINTS
from tests.paths import ROOT

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
#: Stacks of other methods (and of the web server), none of which a phase-plane plan needs.
NOT_FOR_PHASE_PLANE = (
    "cvxpy", "clarabel", "casadi", "ray", "toppra", "matplotlib", "plotly",
    "scipy.optimize", "scipy.sparse", "scipy.interpolate", "fastapi", "starlette", "uvicorn",
)
#: The project's own modules of the other methods (their modules, compiled kernels and the stacks
#: they bring: ruckig, min_cost's process pool), none of which a phase-plane plan needs.
OTHER_METHODS = (
    "ruckig", "multiprocessing", "toptraj.planners.timing.ruckig_method", "toptraj.planners.timing.min_cost",
    "toptraj.planners.timing.jerk.method", "toptraj.planners.execution.isolated",
    "toptraj.planners.generators.search.generator", "toptraj.planners.generators.search.local",
    "toptraj.planners.generators.collocation.generator", "toptraj.planners.generators.collocation.collocation",
)
TYPICAL = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": "spline"},
    "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
    "output": {"dt": 0.01},
}
TOPPRA = {**TYPICAL, "timing": {"method": "toppra", "constraints": ["velocity", "acceleration", "torque"]}}
CUBIC = {"robot": "panda", "path": {"kind": "waypoints", "waypoints": [[0, -0.5, 0, -2, 0, 1.5, 0.7], [0.6, -0.2, 0.3, -1.6, 0.2, 1.8, 0.9]]},
         "timing": {"method": "cubic", "constraints": ["velocity", "acceleration"]}}
#: A fresh interpreter: ``toptraj plan FILE`` (toptraj.service.cli.main), then the modules it holds.
_PLAN = """
import json, sys
from toptraj.service.cli import main
status = main(["plan", sys.argv[1]])
sys.stdout.flush()
print(json.dumps(sorted(sys.modules)), file=sys.stderr)
sys.exit(status)
"""


def _python(code: str, *args: str) -> subprocess.CompletedProcess:
    done = subprocess.run([sys.executable, "-c", code, *args], cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return done


def _loaded(modules: list[str], names: tuple[str, ...]) -> list[str]:
    return [name for name in names if name in modules]


@pytest.mark.parametrize(
    ("request_body", "needed", "not_needed"),
    [
        # numba too, unless the install's library holds the kernels (tests/compiled/)
        (TYPICAL, ("pinocchio", "toptraj.planners.timing.phase_plane.method"),
         (*NOT_FOR_PHASE_PLANE, *OTHER_METHODS, "toptraj.planners.timing.toppra_method")),
        (TOPPRA, ("toppra", "toptraj.planners.timing.toppra_method"), ("cvxpy", "clarabel", "casadi", "ray", "plotly", "fastapi", "uvicorn", *OTHER_METHODS)),
    ],
    ids=["phase_plane", "toppra"],
)
def test_toptraj_plan_imports_only_what_its_method_needs(tmp_path, request_body, needed, not_needed):
    request = tmp_path / "request.json"
    request.write_text(json.dumps(request_body))
    done = _python(_PLAN, str(request))
    answer = json.loads(done.stdout)
    modules = json.loads(done.stderr.strip().splitlines()[-1])
    assert answer["method"] == request_body["timing"]["method"] and answer["duration"] > 0
    assert _loaded(modules, needed) == list(needed)
    assert _loaded(modules, not_needed) == []


#: A fresh interpreter: a server's start-up (the app's lifespan, as ``toptraj serve`` runs it),
#: the numba compilations during it, its log, ``/health``, and the modules it holds.
_START = """
import json, logging, sys
from numba.core import event
from fastapi.testclient import TestClient
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

lines = []
handler = logging.Handler()
handler.emit = lambda record: lines.append(record.getMessage())
logging.getLogger("uvicorn.error").addHandler(handler)
logging.getLogger("uvicorn.error").setLevel(logging.INFO)
with event.install_recorder("numba:compile") as compiled:
    with TestClient(create_app(Settings(data_dir=sys.argv[1]))) as client:
        health = client.get("/health").status_code
        modules = sorted(sys.modules)
print(json.dumps({"compiled": sum(1 for _, e in compiled.buffer if e.is_end), "health": health, "lines": lines, "modules": modules}))
"""


def test_a_server_with_a_warm_cache_starts_without_compiling_or_heavy_imports(tmp_path):
    """The bound is in events: once the install's step has run (here: the server's steps, in a
    process of their own), a start compiles no kernel, imports none of the stacks that run in
    the fork server's children or in methods not yet asked for, and says each step."""
    _python("from toptraj.service.warmup import run_steps, server_steps; run_steps(server_steps(), print)")
    started = json.loads(_python(_START, str(tmp_path)).stdout.strip().splitlines()[-1])
    assert started["health"] == 200
    assert started["compiled"] == 0
    assert _loaded(started["modules"], ("cvxpy", "clarabel", "casadi", "toppra", "matplotlib", "ray", "plotly", "scipy.optimize")) == []
    steps = [line for line in started["lines"] if line.startswith("toptraj start-up [")]
    assert any("phase-plane kernels: done" in line and "nothing to compile" in line for line in steps), started["lines"]
    assert len(steps) >= 6  # a line as each of the three steps begins and one as it ends


#: A fresh interpreter: answers of a few requests as the service renders them (all but
#: ``solve_ms``, the wall time the planning took), with the server's warm-up first (``warm``) or
#: without it.
_ANSWERS = """
import hashlib, json, sys
if sys.argv[1] == "warm":
    from toptraj.service.warmup import run_steps, server_steps
    run_steps(server_steps(), lambda line: None)
from toptraj.service.planning import plan_request, render
from toptraj.service.schemas.trajectories import TrajectoryRequest
answers = {}
for name, body in json.loads(sys.argv[2]).items():
    request = TrajectoryRequest.model_validate(body)
    answer = json.loads(render(plan_request(request), request)[0])
    del answer["solve_ms"]
    answers[name] = hashlib.sha256(json.dumps(answer, sort_keys=True).encode()).hexdigest()
print(json.dumps(answers))
"""


def test_warm_start_up_does_not_change_any_answer():
    requests = json.dumps({"typical": TYPICAL, "toppra": TOPPRA, "cubic": CUBIC})
    cold = json.loads(_python(_ANSWERS, "cold", requests).stdout.strip().splitlines()[-1])
    warm = json.loads(_python(_ANSWERS, "warm", requests).stdout.strip().splitlines()[-1])
    assert set(cold) == {"typical", "toppra", "cubic"}
    assert warm == cold


def test_a_long_start_up_step_is_said_again_until_it_ends(monkeypatch):
    """Never silent: a step that lasts is reported as it begins, again every ``HEARTBEAT_S``
    while it lasts (here it ends only once two such lines came), and as it ends."""
    import threading

    from toptraj.service import warmup

    monkeypatch.setattr(warmup, "HEARTBEAT_S", 0.01)
    lines: list[str] = []
    two_said = threading.Event()

    def report(line: str) -> None:
        lines.append(line)
        if sum(line.startswith("still loading") for line in lines) >= 2:
            two_said.set()

    def long_step() -> None:
        assert two_said.wait(60), lines

    assert warmup.run_steps([("loading", long_step)], report) == 0
    assert lines[0] == "loading ..." and lines[1].startswith("still loading") and lines[-1].startswith("loading: done in")
    said = len(lines)
    threading.Event().wait(0.1)  # the heartbeat ended with the step
    assert len(lines) == said


_BYTECODE = """
import importlib.util, json, os, sys
from toptraj.service.warmup import write_bytecode
write_bytecode()
package = os.path.dirname(importlib.util.find_spec("toptraj").origin)
sources = [os.path.join(folder, name) for folder, _, names in os.walk(package, followlinks=True)
           for name in names if name.endswith(".py")]
print(json.dumps({"sources": len(sources), "missing": [s for s in sources if not os.path.exists(importlib.util.cache_from_source(s))]}))
"""


def test_the_install_writes_the_bytecode_even_where_python_would_not(tmp_path):
    """Where the environment forbids writing bytecode on import (the Dockerfile's
    ``PYTHONDONTWRITEBYTECODE``), every start would compile toptraj's modules from their
    sources: the install's step writes them all (here under a fresh ``PYTHONPYCACHEPREFIX``)."""
    env = {**ENV, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPYCACHEPREFIX": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", _BYTECODE], cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    written = json.loads(done.stdout.strip().splitlines()[-1])
    assert written["sources"] > 150 and written["missing"] == []
