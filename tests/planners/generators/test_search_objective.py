"""The local optimization's compiled objective (``toptraj.planners.generators.search.objective_kernels``)
against the reference path it replaces (``BSplinePath``, ``build_path_constraints``,
``midpoint_duration``, ``free_distances``): the same J(P) to 1e-12 relative on random control
points of three arms (the Geering arm under torque limits, ur5 under velocity, acceleration and
torque limits, panda with its viscous friction), with the obstacle and joint-range penalties
active, and on paths no timing can follow."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners.collision import BoxObstacle, CapsuleObstacle, SphereObstacle
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.generators.search.local import dyadic_knots
from toptraj.planners.generators.search.local_objective import INFEASIBLE, Objective
from toptraj.planners.generators.search.local_outcome import LocalSettings

ALL = ("velocity", "acceleration", "torque")
#: arm: (start, goal, limit kinds, obstacles, clearance)
CASES = {
    "geering_2r": ([0.0, 0.0], [0.76, 0.0], ("torque",), (SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05),), 0.01),
    "ur5": (
        [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0], [1.0, -1.2, 1.5, -1.9, -1.57, 0.0], ALL,
        (BoxObstacle(np.array([0.626, 0.109, 0.29]), np.array([0.15, 0.15, 0.15])),), 0.02,
    ),
    "panda": (
        [-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8], [0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8], ALL,
        (
            BoxObstacle(np.array([0.4854, 0.0, 0.491]), np.array([0.1, 0.1, 0.1])),
            CapsuleObstacle(np.array([0.3, -0.4, 0.1]), np.array([0.5, 0.4, 0.6]), 0.04),
        ),
        0.01,
    ),
}


def search_objective(arm: str, torque_scale: float = 1.0) -> Objective:
    """The local optimization's objective of case ``arm`` (``CASES``), its torque limits
    scaled by ``torque_scale``, with the default settings and no deadline."""
    start, goal, kinds, obstacles, clearance = CASES[arm]
    robot = robots.load(arm)
    limits = dataclasses.replace(robot.limits, torque=robot.limits.torque * torque_scale)
    return Objective(robot, limits, kinds, np.array(start), np.array(goal), obstacles, clearance, LocalSettings(), NO_DEADLINE)


def random_points(objective: Objective, count: int, spread: float, rng: np.random.Generator) -> np.ndarray:
    """Interior control points (count - 2 of them, flattened) scattered by ``spread`` (rad)
    about the straight joint line."""
    line = np.linspace(objective.start, objective.goal, count)[1:-1]
    return (line + rng.normal(scale=spread, size=line.shape)).ravel()


@pytest.mark.parametrize("arm", list(CASES))
def test_the_compiled_objective_equals_the_reference_path(arm):
    objective = search_objective(arm)
    assert objective.fused
    rng = np.random.default_rng(7)
    penalized = 0
    for count in (4, 5, 9, 13):
        objective.interior = np.sort(dyadic_knots(count - 4))
        for spread in (0.05, 0.3, 1.0):
            x = random_points(objective, count, spread, rng)
            reference = objective.reference(x)
            assert objective.value(x) == pytest.approx(reference, rel=1e-12, abs=0.0)
            penalized += objective.penalty(objective.path(x)) > 0.0
            assert reference < INFEASIBLE  # the limits can be held along these paths
    assert penalized >= 3  # the penalties are compared too, not only durations


def test_a_path_no_timing_can_follow_gets_the_same_objective():
    """ur5 with a twentieth of its torques cannot hold its own weight: every path is
    infeasible, its objective ``INFEASIBLE`` plus the same penalties."""
    objective = search_objective("ur5", torque_scale=0.05)
    rng = np.random.default_rng(3)
    objective.interior = np.sort(dyadic_knots(3))
    for spread in (0.05, 0.5):
        x = random_points(objective, 7, spread, rng)
        reference = objective.reference(x)
        assert reference >= INFEASIBLE
        assert objective.value(x) == pytest.approx(reference, rel=1e-12, abs=0.0)


def test_the_knots_of_a_new_round_give_new_basis_weights():
    """The weights follow the interior knots: the same control points on other knots give the
    reference's other value."""
    objective = search_objective("geering_2r")
    x = random_points(objective, 7, 0.2, np.random.default_rng(5))
    values = []
    for interior in (np.array([0.25, 0.5, 0.75]), np.array([0.125, 0.5, 0.875])):
        objective.interior = interior
        values.append(objective.value(x))
        assert values[-1] == pytest.approx(objective.reference(x), rel=1e-12, abs=0.0)
    assert values[0] != values[1]


def test_limits_the_kernel_does_not_compute_take_the_reference_path():
    """A jerk limit (read by no midpoint timing, but a kind the kernel does not know) sends
    every evaluation down the reference path."""
    start, goal, _, obstacles, clearance = CASES["geering_2r"]
    robot = robots.load("geering_2r")
    objective = Objective(robot, robot.limits, ("torque", "jerk"), np.array(start), np.array(goal), obstacles, clearance, LocalSettings(), NO_DEADLINE)
    assert not objective.fused
    x = random_points(objective, 4, 0.1, np.random.default_rng(2))
    assert objective.value(x) == objective.reference(x)
