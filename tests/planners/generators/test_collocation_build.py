"""The free-path collocation's IPOPT problem (``toptraj.planners.generators.collocation.sparse``) holds one
inverse-dynamics graph whatever the number of intervals, and reaches the optimum the dense
solver (SLSQP on Pinocchio's RNEA and its analytical derivatives) reaches from the same start;
a motion that its velocity or acceleration limits shape is not sent to the bang-bang
refinement (``toptraj.planners.generators.collocation.generator``)."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import LimitRequest, Sampling, build_problem, plan
from toptraj.planners.generators.collocation import collocation
from toptraj.planners.generators.collocation import generator as collocation_generator
from toptraj.planners.generators.collocation.generator import Collocation
from toptraj.planners.generators.collocation.sparse import SparseCollocation
from toptraj.planners.problem.free_motion import FreeMotion

START = np.array([0.0, -1.2, 1.0, 0.0, 0.3, 0.0])
GOAL = np.array([0.8, -1.0, 1.4, -0.5, 0.6, 0.3])


def _problem(intervals: int):
    robot = robots.load("ur5")
    motion = collocation.FreeMotion(START, GOAL, intervals=intervals, revolutions=False)
    return collocation._Problem(robot, robot.limits, motion, GOAL, 0.0)


def test_the_hessian_of_the_lagrangian_does_not_grow_with_the_intervals():
    """IPOPT's Hessian of the Lagrangian, as CasADi evaluates it: the same instructions on 6 and
    on 24 intervals (one RNEA's second derivatives, mapped over the instants), and a few hundred
    of them (the whole problem written out, instant by instant, holds some 10^5 per 6 intervals)."""
    sizes = [SparseCollocation(_problem(K), 50).solver.get_function("nlp_hess_l").n_instructions() for K in (6, 24)]
    assert sizes[0] == sizes[1]
    assert sizes[0] < 1_000


def test_ipopt_reaches_the_dense_solvers_optimum():
    """ur5 on 8 intervals from the straight line timed along itself: IPOPT's minimum time equals
    the one SLSQP reaches from the same start on the same NLP (to 1e-6), and its motion meets
    the equalities and the torque limits by Pinocchio's RNEA."""
    problem = _problem(8)
    z0 = collocation._timed_guess(problem, np.zeros(6))
    sparse = SparseCollocation(problem, 500).solve(problem, z0)
    dense, feasible = collocation._solve(problem, z0, 500)
    assert sparse.success and feasible
    assert collocation._feasible(problem, sparse.x)
    assert sparse.fun == pytest.approx(dense.fun, rel=1e-6)


def test_a_motion_shaped_by_its_acceleration_limits_is_not_refined_to_bang_bang(monkeypatch):
    """The ur5 free motion under velocity, acceleration and torque limits: its torques stay
    below a third of their limits (the acceleration limits shape it), so no refinement to
    bang-bang torques is tried; the answer is the collocation's path re-timed, within its limits."""
    calls = []
    monkeypatch.setattr(collocation_generator, "refine_collocation", lambda *args, **kwargs: calls.append(args))
    arm = robots.load("ur5")
    result = plan(build_problem(arm, FreeMotion(START, GOAL, intervals=12, revolutions=False), Collocation(), limits=LimitRequest(kinds=("velocity", "acceleration", "torque")), sampling=Sampling(dt=0.01)))
    assert calls == []
    assert result.solver.switching == "read off the samples"
    assert max(result.peak_utilization["torque"]) < 0.5
    assert max(result.peak_utilization["acceleration"]) <= 1.005


def _loaded_phase_plane_signatures() -> int:
    from toptraj.planners.timing.phase_plane.sweep_kernels import sweeps

    return sweeps.loaded()  # from the install's library, or numba's cache


def test_a_worker_starts_with_the_first_guess_kernels_loaded():
    """A worker process (``toptraj.planners.execution.isolated``) starts with the phase-plane kernels
    of the collocation's first guess already loaded, before calling any: its fork server ran
    them once (``toptraj.planners.generators.collocation.warm``)."""
    from toptraj.planners.execution.deadline import Deadline
    from toptraj.planners.execution.isolated import run_isolated

    assert run_isolated(_loaded_phase_plane_signatures, deadline=Deadline(120)) >= 1
