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
from toptraj.planners import Deadline, Timing, WaypointPath, plan
from toptraj.planners.errors import OverMemory, TooLarge
from toptraj.planners.execution import memory
from toptraj.planners.generators.search.generator import Search
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.memory import search_bytes
from toptraj.planners.problem.build import build_problem
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.results import Accuracy
from toptraj.planners.runner.admission import admit
from toptraj.planners.runner.choice import method_for

LINE = np.array([[0.0, 0.0], [0.5, 0.3]])
VIA = np.array([[0.0, 0.0], [0.3, 0.1], [0.5, 0.3]])
FREE = FreeMotion(start=np.zeros(2), goal=np.array([0.5, 0.3]))
#: Samples the answer may hold: 1,000 of 2 joints, 80 kB reserved.
MAX_SAMPLES = 1_000
LARGEST = 40
WITH_JERK = ("velocity", "acceleration", "jerk")
#: The arm's catalog limits only its torques: the other limits are the request's.
LIMITS = {"velocity": [2.0, 2.0], "acceleration": [8.0, 8.0], "jerk": [50.0, 50.0]}

#: (label, path, timing): every method of both families on the two-joint arm.
METHODS = [
    ("phase_plane", LINE, Timing(method="phase_plane")),
    ("toppra", LINE, Timing(method="toppra")),
    ("min_cost", LINE, Timing(method="min_cost", torque_weight=1e-3)),
    ("jerk_limited", LINE, Timing(method="jerk_limited", constraints=WITH_JERK)),
    ("cubic", LINE, Timing(method="cubic")),
    ("quintic", LINE, Timing(method="quintic")),
    ("trapezoidal", LINE, Timing(method="trapezoidal", constraints=("velocity", "acceleration"))),
    ("cycloidal", LINE, Timing(method="cycloidal")),
    ("ruckig", LINE, Timing(method="ruckig", constraints=WITH_JERK)),
    ("via points", VIA, Timing(method="quintic")),
    ("unsynchronized", LINE, Timing(method="cubic", synchronization="none")),
    ("collocation", FREE, Timing(method="collocation")),
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


@pytest.mark.parametrize("label, path, timing", METHODS, ids=[m[0] for m in METHODS])
def test_each_method_is_refused_before_any_work_with_a_grid_that_then_plans(arm, monkeypatch, label, path, timing):
    spec, timing = _path(path), dataclasses.replace(timing, limit_overrides=LIMITS)
    method = method_for(timing, spec)
    monkeypatch.setattr(memory, "MEMORY_CAP_BYTES", _cap_for(method.bytes_per_interval_joint, arm.dof))
    stages: list[str] = []
    deadline = Deadline(progress=lambda fraction, stage: stages.append(stage))
    with pytest.raises(TooLarge) as refused:
        plan(arm, spec, dataclasses.replace(timing, grid_points=LARGEST + 1), deadline=deadline, max_samples=MAX_SAMPLES)
    error = refused.value
    assert stages == []  # nothing started: no stage reported its progress
    assert (error.field, error.value, error.largest, error.method) == ("grid.intervals", LARGEST + 1, LARGEST, method.name)
    assert error.estimate > error.cap
    answer = plan(arm, spec, dataclasses.replace(timing, grid_points=error.largest), max_samples=MAX_SAMPLES)
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
    timing = Timing(method="search", search=dataclasses.replace(options, memory_bytes=allowance))
    with pytest.raises(OverMemory) as refused:
        plan(arm, spec, timing, deadline=Deadline(progress=lambda fraction, stage: stages.append(stage)))
    assert stages == []
    points = refused.value.most_points

    def problem(roadmap_points):
        search = dataclasses.replace(options, roadmap_points=roadmap_points, memory_bytes=allowance)
        return build_problem(arm, spec, Search(search), Timing(method="search", search=search))

    admit(problem(points))
    with pytest.raises(OverMemory):
        admit(problem(points + 1))
    assert search_bytes(arm, start, goal, problem(points).method.options, True) <= allowance
