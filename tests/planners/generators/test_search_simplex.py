"""The local optimization's compiled Nelder-Mead (``toptraj.planners.generators.search.simplex``)
against SciPy's ``minimize(method="Nelder-Mead")`` that it replaces, on the objective of the
Geering arm around a sphere and of ur5 around a box: the same best point and objective to the
last bit after the same evaluations. The ur5 round meets vertices of equal objective (moving
the wrist's last joint changes no limit and no distance), which NumPy's sort orders as in
SciPy's loop. Once its allowance is spent, a round ends at the best point evaluated."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners.collision import BoxObstacle, SphereObstacle
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.generators.search import local, simplex
from toptraj.planners.generators.search.local import dyadic_knots, fit_seed
from toptraj.planners.generators.search.local_objective import Objective
from toptraj.planners.generators.search.local_outcome import LocalSettings


def _geering():
    robot = robots.load("geering_2r")
    sphere = SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05)
    # a seed bent below the sphere: the simplex's vertices cross the clearance
    return robot, np.array([[0.0, 0.0], [0.3, -0.9], [0.76, 0.0]]), ("torque",), (sphere,), 0.01


def _ur5():
    robot = robots.load("ur5")
    start, goal = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    pin.framesForwardKinematics(robot.model, robot.data, robot.configuration(((start + goal) / 2.0)[None])[0])
    tool = np.array(robot.data.oMf[robot.frame_id(robot.end_effector)].translation)
    box = BoxObstacle(tool, np.array([0.1, 0.1, 0.1]))
    return robot, np.array([start, (start + goal) / 2.0 + 0.3, goal]), ("velocity", "acceleration", "torque"), (box,), 0.01


def _round(case, control_points: int, per_variable: int, compiled: bool):
    """One round of ``local._nelder_mead`` from the seed's fitted spline: (x, objective,
    spent, evaluations), by the compiled loop or by SciPy on the same compiled objective."""
    robot, seed, kinds, obstacles, clearance = case()
    settings = LocalSettings(evaluations_per_variable=per_variable)
    objective = Objective(robot, robot.limits, kinds, seed[0], seed[-1], obstacles, clearance, settings, NO_DEADLINE)
    assert objective.fused
    objective.interior = np.sort(dyadic_knots(control_points - 4))
    control = fit_seed(seed, objective.interior)
    extent = np.maximum(np.ptp(seed, axis=0) * settings.step, settings.min_step)
    objective.fused = compiled  # SciPy's loop where False; its evaluations still take the kernel
    objective.value = lambda x: Objective.value(objective, x) if compiled else _fused_value(objective, x)
    x, value, spent = local._nelder_mead(objective, control[1:-1].ravel(), extent)
    return x, value, spent, objective.evaluations, objective


def _fused_value(objective: Objective, x: np.ndarray) -> float:
    from toptraj.planners.generators.search.objective_kernels import objective_value

    return float(objective_value(np.ascontiguousarray(x, dtype=float), *objective.fused_arguments()))


@pytest.mark.parametrize(("case", "control_points", "per_variable"), [(_geering, 5, 100), (_geering, 9, 30), (_ur5, 5, 15)])
def test_the_compiled_nelder_mead_walks_scipys_simplices(case, control_points, per_variable, monkeypatch):
    sorted_by_numpy = []
    numpy_sort = simplex._numpy_sort
    monkeypatch.setattr(simplex, "_numpy_sort", lambda sim, fsim: (sorted_by_numpy.append(1), numpy_sort(sim, fsim)))
    x_scipy, value_scipy, spent_scipy, count_scipy, _ = _round(case, control_points, per_variable, False)
    x, value, spent, count, _ = _round(case, control_points, per_variable, True)
    assert not spent and not spent_scipy
    assert count == count_scipy > 0
    np.testing.assert_array_equal(x, x_scipy)
    assert value == value_scipy
    assert bool(sorted_by_numpy) == (case is _ur5)  # equal objectives, met on ur5 only


def test_a_round_whose_allowance_is_spent_ends_at_the_best_point_evaluated(monkeypatch):
    checks = []

    def check(objective):
        checks.append(1)
        if len(checks) > 3:  # three chunks of evaluations, then the allowance is spent
            raise simplex._Spent

    monkeypatch.setattr(simplex, "_check", check)
    x, value, spent, count, objective = _round(_geering, 9, 100, True)
    # the first simplex's 15 vertices, then two chunks of at least CHUNK_EVALUATIONS each
    assert spent and 15 + 2 * simplex.CHUNK_EVALUATIONS <= count < 15 + 2 * (simplex.CHUNK_EVALUATIONS + 15)
    assert objective.value(x) == value
    monkeypatch.setattr(simplex, "_check", lambda objective: (_ for _ in ()).throw(simplex._Spent()))
    x, value, spent, count, _ = _round(_geering, 9, 100, True)
    assert spent and x is None and count == 0
