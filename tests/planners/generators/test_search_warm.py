"""The fork server of the isolated workers preloads the search's warm-up
(``toptraj.planners.generators.search.warm``) and the runner's (``toptraj.planners.runner.warm``):
a worker forked after them loads no kernel from numba's cache for the searches of any arm (two,
six or seven joints, friction or none), their local optimization and their answer's timing; and
a warm-up step that fails is logged and skipped, so the fork server keeps serving."""

from __future__ import annotations

import logging
import subprocess
import sys

import pytest

from tests.paths import ROOT
from toptraj.planners.execution.isolated import PRELOAD

WARM_UPS = ("toptraj.planners.generators.search.warm", "toptraj.planners.runner.warm")

#: In a fresh process, as in the fork server: the warm-ups, then what a search's worker does on
#: three arms; prints the kernels that loaded or compiled a signature after the warm-ups.
WORKER = """
import importlib
import numpy as np
from toptraj import robots
from toptraj.compiled.kernel import KERNELS
for name in {warm_ups!r}:
    importlib.import_module(name)
before = {{kernel: kernel.loaded() for kernel in KERNELS}}
from toptraj.planners.collision import BoxObstacle, SphereObstacle
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.local import optimize_locally
from toptraj.planners.generators.search.local_outcome import LocalSettings
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.problem.build import build_problem
from toptraj.planners.problem.problem import LimitRequest
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.runner.run import run
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

settings = LocalSettings(max_control_points=5, evaluations_per_variable=3)
arm = robots.load("geering_2r")
sphere = (SphereObstacle(np.array([0.4, 0.4, 0.0]), 0.05),)
found = global_search(arm, arm.limits, ("torque",), np.zeros(2), np.array([0.9, 0.3]), SearchOptions(cells=(10,), tubes=1), True, sphere, 0.01)
optimize_locally(arm, found.result.tubes[0].points, arm.limits, ("torque",), sphere, 0.01, settings=settings)
kinds = ("velocity", "acceleration", "torque")
for name, start, goal in (
    ("ur5", [-0.8, -1.2, 1.5, -1.9, -1.57, 0.0], [0.9, -1.1, 1.4, -1.9, -1.57, 0.2]),
    ("panda", [-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8], [0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]),
):
    robot, start, goal = robots.load(name), np.array(start), np.array(goal)
    box = (BoxObstacle(np.array([0.5, 0.5, 1.5]), np.array([0.1, 0.1, 0.1])),)
    found = global_search(robot, robot.limits, kinds, start, goal, SearchOptions(roadmap_points=6, neighbors=3, tubes=1), True, box, 0.01)
    optimize_locally(robot, found.result.tubes[0].points, robot.limits, kinds, box, 0.01, settings=settings)
    path = WaypointPath(np.array([start, (start + goal) / 2.0 + 0.05, goal]))
    run(build_problem(robot, path, PhasePlaneMethod(), limits=LimitRequest(kinds=kinds)))
print("loaded after the warm-ups:", [repr(kernel) for kernel in KERNELS if kernel.loaded() != before.get(kernel, 0)])
"""


def test_the_fork_server_preloads_the_warm_ups():
    assert all(name in PRELOAD for name in WARM_UPS)


def test_a_worker_forked_after_the_warm_ups_loads_no_kernel():
    done = subprocess.run([sys.executable, "-c", WORKER.format(warm_ups=WARM_UPS)], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip().splitlines()[-1] == "loaded after the warm-ups: []"


@pytest.mark.parametrize(("module", "step"), [("toptraj.planners.generators.search.warm", "global_search"), ("toptraj.planners.runner.warm", "run")])
def test_a_failing_warm_up_is_logged_and_skipped(module, step, monkeypatch, caplog):
    warm = sys.modules.get(module) or __import__(module, fromlist=["warm"])

    def fails(*args, **keywords):
        raise RuntimeError("no grid path")

    monkeypatch.setattr(warm, step, fails)
    with caplog.at_level(logging.WARNING, logger=module):
        warm.warm()  # no exception
    assert any("warm-up" in record.getMessage() and "failed" in record.getMessage() for record in caplog.records)
