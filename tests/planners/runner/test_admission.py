"""One memory admission for every method of both families: before any work, the grid's bytes
(the method's bytes per interval and joint), the samples reserved and a generator's own
estimate are held to one cap; over it, the refusal names the largest grid that fits, and that
grid is planned.

The cap is lowered here so that each method's largest grid is ``LARGEST`` intervals on the
two-joint arm: a grid one larger is refused before any progress is reported, and the advice
is followed to an answer.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS as BY_NAME
from toptraj.planners import Deadline, WaypointPath, plan
from toptraj.planners.errors import OverMemory, TooLarge
from toptraj.planners.execution import memory
from toptraj.planners.generators.collocation.generator import Collocation
from toptraj.planners.generators.joint_moves import Unsynchronized, ViaPoints
from toptraj.planners.generators.search.generator import Search
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.memory import search_bytes
from toptraj.planners.problem.build import build_problem
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.problem import LimitRequest, Sampling
from toptraj.planners.results import Accuracy
from toptraj.planners.runner.admission import admit
from toptraj.planners.timing.min_cost import MinCostMethod

LINE = np.array([[0.0, 0.0], [0.5, 0.3]])
VIA = np.array([[0.0, 0.0], [0.3, 0.1], [0.5, 0.3]])
FREE = FreeMotion(start=np.zeros(2), goal=np.array([0.5, 0.3]))
#: Samples the answer may hold: 1,000 of 2 joints, 80 kB reserved.
MAX_SAMPLES = 1_000
LARGEST = 40
WITH_JERK = ("velocity", "acceleration", "jerk")
#: The arm's catalog limits only its torques: the other limits are the request's.
LIMITS = {"velocity": [2.0, 2.0], "acceleration": [8.0, 8.0], "jerk": [50.0, 50.0]}

#: (label, path, method, kinds): every method of both families on the two-joint arm.
ALL_KINDS = ("velocity", "acceleration", "torque")
METHODS = [
    ("phase_plane", LINE, BY_NAME["phase_plane"], ALL_KINDS),
    ("toppra", LINE, BY_NAME["toppra"], ALL_KINDS),
    ("min_cost", LINE, MinCostMethod(1e-3), ALL_KINDS),
    ("jerk_limited", LINE, BY_NAME["jerk_limited"], WITH_JERK),
    ("cubic", LINE, BY_NAME["cubic"], ALL_KINDS),
    ("quintic", LINE, BY_NAME["quintic"], ALL_KINDS),
    ("trapezoidal", LINE, BY_NAME["trapezoidal"], ("velocity", "acceleration")),
    ("cycloidal", LINE, BY_NAME["cycloidal"], ALL_KINDS),
    ("ruckig", LINE, BY_NAME["ruckig"], WITH_JERK),
    ("via points", VIA, ViaPoints(BY_NAME["quintic"]), ALL_KINDS),
    ("unsynchronized", LINE, Unsynchronized(BY_NAME["cubic"]), ALL_KINDS),
    ("collocation", FREE, Collocation(), ALL_KINDS),
]


def _path(path):
    if isinstance(path, FreeMotion):
        return path
    return WaypointPath(path, interpolation="via") if path is VIA else WaypointPath(path)


def _cap_for(bytes_per_interval_joint: int, dof: int) -> int:
    """A cap under which ``LARGEST`` intervals fit beside the samples, and one more does not:
    the figures of the rule, 5 eight-byte arrays per sample and joint, written out here."""
    samples = MAX_SAMPLES * dof * 5 * 8
    return samples + LARGEST * dof * bytes_per_interval_joint + bytes_per_interval_joint * dof - 1


@pytest.fixture(scope="module")
def arm():
    return robots.load("yamamoto_2r")


@pytest.mark.parametrize("label, path, method, kinds", METHODS, ids=[m[0] for m in METHODS])
def test_each_method_is_refused_before_any_work_with_a_grid_that_then_plans(arm, monkeypatch, label, path, method, kinds):
    spec, limits = _path(path), LimitRequest(kinds=kinds, overrides=LIMITS)
    monkeypatch.setattr(memory, "MEMORY_CAP_BYTES", _cap_for(method.bytes_per_interval_joint, arm.dof))
    stages: list[str] = []
    deadline = Deadline(progress=lambda fraction, stage: stages.append(stage))
    sampling = Sampling(max_samples=MAX_SAMPLES)
    with pytest.raises(TooLarge) as refused:
        plan(build_problem(arm, spec, method, limits=limits, grid=LARGEST + 1, sampling=sampling, deadline=deadline))
    error = refused.value
    assert stages == []  # nothing started: no stage reported its progress
    assert (error.field, error.value, error.largest, error.method) == ("grid.intervals", LARGEST + 1, LARGEST, method.name)
    assert error.estimate > error.cap
    answer = plan(build_problem(arm, spec, method, limits=limits, grid=error.largest, sampling=sampling))
    assert answer.duration > 0.0 and len(answer.samples.t) >= 2
    assert isinstance(answer.accuracy, Accuracy) and answer.accuracy.basis  # stated by the runner


def test_a_search_over_its_memory_is_refused_before_any_work_with_a_roadmap_that_is_admitted():
    """The search's graph against its own allowance (``memory_bytes``): the refusal names the
    most roadmap points that fit, which the admission takes and one more it refuses (a whole
    search takes tens of seconds; ``tests/planners/generators/test_search_budget.py`` plans
    one at the advice over HTTP)."""
    arm = robots.load("geering_2r")
    start, goal = np.zeros(2), np.array([0.76, 0.0])
    options = SearchOptions(graph="roadmap", roadmap_points=200, neighbors=8, tubes=1)
    allowance = search_bytes(arm, start, goal, options, True) // 3
    spec = FreeMotion(start=start, goal=goal)
    stages: list[str] = []
    method = Search(dataclasses.replace(options, memory_bytes=allowance))
    with pytest.raises(OverMemory) as refused:
        plan(build_problem(arm, spec, method, deadline=Deadline(progress=lambda fraction, stage: stages.append(stage))))
    assert stages == []
    points = refused.value.most_points

    def problem(roadmap_points):
        search = dataclasses.replace(options, roadmap_points=roadmap_points, memory_bytes=allowance)
        return build_problem(arm, spec, Search(search))

    admit(problem(points))
    with pytest.raises(OverMemory):
        admit(problem(points + 1))
    assert search_bytes(arm, start, goal, problem(points).method.options, True) <= allowance
