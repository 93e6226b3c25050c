"""The free-path collocation on a sparse NLP solver (IPOPT through CasADi): its symbolic
inverse dynamics against Pinocchio, Yamamoto's converged minimum time, and ur5 at 30 intervals."""

from __future__ import annotations

import numpy as np
import pytest

from tests.planners.generators.test_free_path import YAMAMOTO_MINIMUM_TIME
from toptraj import robots
from toptraj.planners.generators.collocation import collocation
from toptraj.planners.generators.collocation.sparse import solve_sparse
from toptraj.planners.generators.collocation.symbolic_dynamics import inverse_dynamics_function


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova", "geering_2r", "yamamoto_2r", "lecture_3r"])
def test_the_symbolic_dynamics_equal_pinocchio_rnea(name):
    robot = robots.load(name)
    function = inverse_dynamics_function(robot)
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 30, robot.dof))
    expected = robot.rnea(q, qd, qdd)
    got = np.array(function.map(30)(q.T, qd.T, qdd.T)).T
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-10 * np.abs(expected).max())


def _solve(name, start, goal, intervals, revolutions=True, beta=0.0):
    robot = robots.load(name)
    motion = collocation.FreeMotion(np.asarray(start), np.asarray(goal), intervals=intervals, revolutions=revolutions)
    problem = collocation._Problem(robot, robot.limits, motion, motion.goal, beta)
    result = solve_sparse(problem, collocation._timed_guess(problem, np.zeros(robot.dof)), 3000)
    assert result.success, result.message
    assert np.abs(problem.defects(result.x)).max() < 1e-8
    assert problem.torque_margin(result.x).min() > -1e-6
    return problem, result


def test_yamamoto_minimum_time_converges_to_the_reference():
    """The converged minimum time of Yamamoto's free path, 0.2059855 s (``YAMAMOTO_MINIMUM_TIME``:
    ``benchmarks/yamamoto_reference.py``, Hermite-Simpson, the same to 7 digits on 400 to 1,600
    intervals), reached here by the planner's own transcription (piecewise-linear
    accelerations, second order in the interval) on 400 intervals: within 2e-6 s (measured
    3.5e-7 s)."""
    _, result = _solve("yamamoto_2r", np.radians([45.0, -90.0]), np.radians([-90.0, 0.0]), 400)
    assert result.fun == pytest.approx(YAMAMOTO_MINIMUM_TIME, abs=2e-6)


def test_the_dense_solver_stays_at_the_sparse_solvers_optimum():
    """IPOPT's answer (Yamamoto, 12 intervals) is a local optimum of the same NLP for the dense
    solver too: SLSQP started there stays there, within its tolerance."""
    problem, result = _solve("yamamoto_2r", np.radians([45.0, -90.0]), np.radians([-90.0, 0.0]), 12)
    dense, feasible = collocation._solve(problem, result.x, 200)
    assert feasible
    assert dense.fun == pytest.approx(result.fun, rel=1e-7)


def test_ur5_free_path_at_30_intervals():
    """A 6-joint free path on 30 intervals (benchmarks/free_path.py times it): a feasible
    motion, shorter than on 12 intervals (the finer mesh places the switches better)."""
    start, goal = [0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]
    fine_problem, fine = _solve("ur5", start, goal, 30, revolutions=False)
    _, coarse = _solve("ur5", start, goal, 12, revolutions=False)
    assert fine.fun < coarse.fun
    T, q, v, a = fine_problem.unpack(fine.x)
    assert q[0] == pytest.approx(start, abs=1e-9) and q[-1] == pytest.approx(goal, abs=1e-9)
    assert np.all(np.abs(v).max(axis=0) <= robots.load("ur5").limits.velocity * (1 + 1e-6))
