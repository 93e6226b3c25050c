"""Torques interpolated from a grid's rows (``toptraj.planners.constraints.torque_interpolation``) against
Pinocchio's RNEA: the dense check's torques between grid points (within
``TOLERANCE`` of the limit where interpolated, RNEA itself where the grid does not
resolve the rows, interpolated at most states of an ordinary request); and the rows a
refinement adds, which are the RNEA's own."""

from __future__ import annotations

import numpy as np
import pytest

from tests.paths import DATA
from toptraj import robots
from toptraj.planners.checks.limit_check import _torques, joint_motion
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.constraints.torque_interpolation import MAX_TRAVEL
from toptraj.planners.paths import SplinePath, StopAndGoPath
from toptraj.planners.paths.blended import BlendedPath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing import PhasePlaneMethod, ToppraMethod
from toptraj.robots import Robot
from toptraj.robots.catalog import robot_from_model
from toptraj.robots.urdf_check import check_urdf

KINDS = ("velocity", "acceleration", "torque")
#: Largest error of an interpolated torque, as a fraction of the joint's torque limit: 1e-5, a
#: 300th of the 0.3 % the gate lets a limit be exceeded by on the dense check.
TOLERANCE = 1e-5


class _CountingRnea:
    """Counts the states whose torques go to ``Robot.inverse_dynamics``."""

    def __init__(self, monkeypatch):
        self.states = 0
        original = Robot.inverse_dynamics

        def counted(robot, q, qd, qdd, direction=None):
            self.states += len(np.atleast_2d(q))
            return original(robot, q, qd, qdd, direction)

        monkeypatch.setattr(Robot, "inverse_dynamics", counted)


def _wide_path(robot, seed: int, spread: float = 3.0):
    rng = np.random.default_rng(seed)
    lower = np.maximum(robot.limits.position_lower, -spread)
    upper = np.minimum(robot.limits.position_upper, spread)
    return SplinePath(rng.uniform(lower, upper, (int(rng.integers(2, 6)), robot.dof)))


def _timed_states(robot, path, grid, method=None):
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, grid)
    timing = (method or ToppraMethod()).solve(constraints)
    states = timing.dense_states(5, constraints.s)
    return constraints, states, joint_motion(path, states)


@pytest.mark.parametrize("name", ["ur5", "yamamoto_2r", "panda"])
@pytest.mark.parametrize("intervals", [30, 60, 120])
def test_within_tolerance_on_coarse_grids_of_wide_motions(name, intervals):
    """Moves of up to 6 rad per joint on coarse grids, where a cubic and a quartic through the
    rows can agree with each other and both miss the torque (by 3.6e-5 of the limit on ur5
    with 60 intervals): the grid's travel decides, and every state stays within tolerance.
    Every one of the ten paths is timed (a timing that raises fails the test)."""
    robot = robots.load(name)
    worst = 0.0
    for seed in range(10):
        path = _wide_path(robot, seed)
        grid = np.unique(np.concatenate([np.linspace(0.0, 1.0, intervals + 1), path.knots]))
        constraints, states, (q, qd, qdd, _) = _timed_states(robot, path, grid)
        tau = _torques(robot, states, q, qd, qdd, constraints)
        worst = max(worst, float(np.max(np.abs(tau - robot.inverse_dynamics(q, qd, qdd)) / robot.limits.torque)))
    assert worst <= TOLERANCE


def test_a_grid_that_does_not_resolve_the_rows_gets_rnea(monkeypatch):
    """Every interval of a 12-interval grid over a 3-waypoint path moves the joints by more
    than ``MAX_TRAVEL``: every state off the grid is computed by RNEA."""
    robot = robots.load("ur5")
    path = SplinePath(np.array([[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]]))
    grid = path_grid(path, 12)
    constraints, states, (q, qd, qdd, _) = _timed_states(robot, path, grid)
    assert np.all(np.abs(np.diff(path.evaluate(grid).q, axis=0)).sum(axis=1) > MAX_TRAVEL)
    counter = _CountingRnea(monkeypatch)
    tau = _torques(robot, states, q, qd, qdd, constraints)
    assert counter.states == np.count_nonzero(~np.isin(states.s, grid) | (states.sd == 0.0))
    monkeypatch.undo()
    np.testing.assert_allclose(tau, robot.inverse_dynamics(q, qd, qdd), rtol=0, atol=1e-12 * robot.limits.torque.max())


def test_with_coulomb_friction_the_states_between_grid_points_get_rnea(monkeypatch):
    """Coulomb friction sits in c with its sign at each grid point: on the friction pendulum
    every state off the grid (or at rest) goes to RNEA, and every torque is RNEA's (with the
    URDF's friction) to rounding, on a grid fine enough to be interpolated without it."""
    text = (DATA / "pendulum_1r.urdf").read_text()
    pendulum = robot_from_model("pendulum_1r", check_urdf(text), "upload", None)
    assert np.any(pendulum.coulomb_friction)
    path = SplinePath(np.array([[-0.5], [0.4], [1.0]]))
    constraints, states, (q, qd, qdd, _) = _timed_states(pendulum, path, path_grid(path), PhasePlaneMethod())
    assert np.all(np.abs(np.diff(constraints.q, axis=0)).sum(axis=1) <= MAX_TRAVEL)
    counter = _CountingRnea(monkeypatch)
    tau = _torques(pendulum, states, q, qd, qdd, constraints)
    assert counter.states == np.count_nonzero(~np.isin(states.s, constraints.s) | (states.sd == 0.0))
    monkeypatch.undo()
    np.testing.assert_allclose(tau, pendulum.inverse_dynamics(q, qd, qdd), rtol=0, atol=1e-12 * pendulum.limits.torque.max())


def test_most_states_of_an_ordinary_request_are_interpolated(monkeypatch):
    """The typical request's path on its default grid: fewer than a tenth of the states off the
    grid need RNEA, and the torques are within a hundredth of the tolerance."""
    robot = robots.load("ur5")
    waypoints = [[0, -1.2, 1, 0, 0, 0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]]
    path = SplinePath(np.array(waypoints, dtype=float))
    constraints, states, (q, qd, qdd, _) = _timed_states(robot, path, path_grid(path), PhasePlaneMethod())
    between = np.count_nonzero(~np.isin(states.s, constraints.s))
    counter = _CountingRnea(monkeypatch)
    tau = _torques(robot, states, q, qd, qdd, constraints)
    assert counter.states < 0.1 * between
    monkeypatch.undo()
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, qd, qdd)) / robot.limits.torque) <= 0.01 * TOLERANCE


def test_rows_are_not_interpolated_across_a_corner():
    """A stop-and-go path: the rows jump at the corner, and the states beside it keep RNEA's
    torques (interpolation never reaches over the corner)."""
    robot = robots.load("ur5")
    path = StopAndGoPath(np.array([[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.3, -1.1, 1.2, -0.2, 0.2, 0.1], [0.1, -1.3, 1.1, 0.1, 0.3, 0.3]]))
    constraints, states, (q, qd, qdd, _) = _timed_states(robot, path, path_grid(path))
    tau = _torques(robot, states, q, qd, qdd, constraints)
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, qd, qdd)) / robot.limits.torque) <= TOLERANCE


def test_rows_are_not_interpolated_across_a_break_of_the_curvature():
    """A blended path: q'' jumps where a straight piece meets a blend, and so does the row b;
    states next to those breaks stay within tolerance."""
    robot = robots.load("ur5")
    waypoints = np.array([[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.6, -1.0, 1.3, -0.4, 0.5, 0.2], [1.2, -1.3, 1.1, 0.1, 0.3, 0.9]])
    path = BlendedPath(waypoints, 0.1)
    assert len(path.breaks)
    constraints, states, (q, qd, qdd, _) = _timed_states(robot, path, path_grid(path), PhasePlaneMethod())
    tau = _torques(robot, states, q, qd, qdd, constraints)
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, qd, qdd)) / robot.limits.torque) <= TOLERANCE


@pytest.mark.parametrize("case", ["ur5", "panda", "yamamoto_2r", "pendulum_coulomb", "ur5_corners"])
def test_refinement_rows_are_the_rows_of_a_build_on_the_refined_grid(case, monkeypatch):
    """Rows at the midpoints of every other interval of a default grid (what a phase-plane
    refinement adds; with Coulomb friction, and on a path with corners, every interval): the
    refined constraints equal, bit for bit, those built afresh on the refined grid, with one
    RNEA per new point and none at the points already there."""
    import toptraj.planners.constraints.path_constraints as constraints_module

    if case == "pendulum_coulomb":
        text = (DATA / "pendulum_1r.urdf").read_text()
        robot = robot_from_model("pendulum_1r", check_urdf(text), "upload", None)
        assert np.any(robot.coulomb_friction)
        path = SplinePath(np.array([[-0.5], [0.4], [1.0]]))
    elif case == "ur5_corners":
        robot = robots.load("ur5")
        path = StopAndGoPath(np.array([[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.3, -1.1, 1.2, -0.2, 0.2, 0.1], [0.1, -1.3, 1.1, 0.1, 0.3, 0.3]]))
    else:
        robot = robots.load(case)
        rng = np.random.default_rng(3)
        lower = np.maximum(robot.limits.position_lower, -2.0)
        upper = np.minimum(robot.limits.position_upper, 2.0)
        path = SplinePath(rng.uniform(0.5 * lower, 0.5 * upper, (4, robot.dof)))
    grid = path_grid(path)
    step = 1 if case in ("pendulum_coulomb", "ur5_corners") else 2
    extra = 0.5 * (grid[:-1] + grid[1:])[::step]
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, grid)
    evaluated = []
    original = constraints_module._rnea_terms

    def counted(robot_, q, dq, ddq):
        evaluated.append(len(q))
        return original(robot_, q, dq, ddq)

    monkeypatch.setattr(constraints_module, "_rnea_terms", counted)
    refined = constraints.with_points(extra)
    monkeypatch.undo()
    assert sum(evaluated) == len(extra)
    fresh = build_path_constraints(path, robot, robot.limits, KINDS, refined.s)
    for name in ("s", "sd_max", "a", "b", "c", "d", "a_left", "b_left", "c_left", "d_left", "lower", "upper", "velocity_joint", "q"):
        np.testing.assert_array_equal(getattr(refined, name), getattr(fresh, name), err_msg=name)
    np.testing.assert_array_equal(refined.smooth, fresh.smooth)
