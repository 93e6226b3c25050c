"""The runner isolates what cannot be interrupted, and nothing else: a method whose capabilities
say it cannot check its deadline (``interruptible`` false) runs its uninterruptible step in a
worker process under a deadline (``Execution.uninterruptible``); the typical request starts
none."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import Deadline, WaypointPath, plan
from toptraj.planners.execution import isolated
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.generators.collocation.generator import Collocation
from toptraj.planners.generators.joint_moves import ViaPoints
from toptraj.planners.generators.search.generator import Search
from toptraj.planners.problem.build import build_problem
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.runner.run import isolates
from toptraj.planners.timing import METHODS
from toptraj.planners.timing.min_cost import MinCostMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

UR5_LINE = np.array([[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]])


def test_each_method_states_whether_it_can_be_interrupted():
    stated = {name: method.interruptible for name, method in METHODS.items()}
    assert stated.pop("min_cost") is False  # cvxpy and Clarabel: one call that checks nothing
    assert all(stated.values()), stated
    assert Collocation().interruptible is False and Search().interruptible is False
    assert ViaPoints(METHODS["quintic"]).interruptible is True


def test_the_runner_isolates_only_an_uninterruptible_method_under_a_deadline(monkeypatch):
    budget = Deadline(10.0)
    assert isolates(Collocation(), budget) and isolates(Search(), budget) and isolates(MinCostMethod(), budget)
    assert not isolates(PhasePlaneMethod(), budget) and not isolates(ViaPoints(METHODS["cubic"]), budget)
    assert not isolates(Collocation(), NO_DEADLINE)  # a library call without a deadline: nothing to stop it for
    monkeypatch.setattr(isolated, "_in_worker", True)
    assert not isolates(Collocation(), budget)  # a job's worker is killed whole


@pytest.fixture
def started(monkeypatch):
    """Counts the worker processes started (each takes the multiprocessing context)."""
    count = []
    real = isolated._get_context

    def counted():
        count.append(1)
        return real()

    monkeypatch.setattr(isolated, "_get_context", counted)
    return count


def test_the_typical_request_starts_no_worker_process(started):
    answer = plan(build_problem(robots.load("ur5"), WaypointPath(UR5_LINE), METHODS["phase_plane"], deadline=Deadline(60.0)))
    assert answer.duration > 0.0 and started == []


def test_the_collocation_optimizes_in_a_worker_process_under_a_deadline(started):
    arm = robots.load("yamamoto_2r")
    motion = FreeMotion(start=np.zeros(2), goal=np.array([0.5, 0.3]))
    answer = plan(build_problem(arm, motion, Collocation(), grid=10, deadline=Deadline(120.0)))
    assert answer.method == "collocation" and len(started) == 1
