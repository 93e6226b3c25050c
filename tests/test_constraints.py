"""PathConstraints: the rows reproduce the robot's torques and accelerations exactly."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robots
from planners.constraints import build_path_constraints
from planners.grid import path_grid
from planners.paths import SplinePath, StopAndGoPath

RNG = np.random.default_rng(3)


@pytest.mark.parametrize("name", ["ur5", "panda", "xarm7", "geering_2r", "yamamoto_2r"])
def test_torque_rows_equal_inverse_dynamics(name):
    """a u + b x + c + d sd equals tau(q, q' sd, q' u + q'' x), computed with pin.rnea here
    (plus the URDF's friction, which xarm7 has)."""
    robot = robots.load(name)
    lower = np.maximum(robot.limits.position_lower, -2.0)
    upper = np.minimum(robot.limits.position_upper, 2.0)
    waypoints = RNG.uniform(lower, upper, (4, robot.dof))
    path = SplinePath(waypoints)
    s = path_grid(path, 40)
    constraints = build_path_constraints(path, robot, robot.limits, ("torque",), s)
    points = path.evaluate(s)
    data = robot.model.createData()
    for i in range(0, len(s), 7):
        u, sd = RNG.normal(0, 3), abs(RNG.normal(0, 2))
        x = sd**2
        qd = points.dq[i] * sd
        qdd = points.dq[i] * u + points.ddq[i] * x
        expected = pin.rnea(robot.model, data, robot.configuration(points.q[i]), qd, qdd)
        expected = expected + robot.viscous_friction * qd + robot.coulomb_friction * np.sign(qd)
        rows = constraints.a[i] * u + constraints.b[i] * x + constraints.c[i] + constraints.d[i] * sd
        assert rows == pytest.approx(expected, abs=1e-9)
    assert constraints.upper[0] == pytest.approx(robot.limits.torque)


def test_velocity_bound_and_acceleration_rows():
    robot = robots.load("ur5")
    path = SplinePath(RNG.uniform(-1, 1, (3, 6)))
    s = path_grid(path, 30)
    constraints = build_path_constraints(path, robot, robot.limits, ("velocity", "acceleration"), s)
    points = path.evaluate(s)
    assert constraints.sd_max == pytest.approx(np.min(robot.limits.velocity / np.abs(points.dq), axis=1))
    assert constraints.a == pytest.approx(points.dq)
    assert constraints.b == pytest.approx(points.ddq)
    assert [kind for kind, _ in constraints.rows] == ["acceleration"] * 6


def test_corners_stop_the_motion_and_keep_both_sides():
    robot = robots.load("ur5")
    waypoints = np.array([[0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 0], [1, 1, 0, 0, 0, 0.0]])
    path = StopAndGoPath(waypoints)
    s = path_grid(path, 20)
    constraints = build_path_constraints(path, robot, robot.limits, ("velocity", "acceleration"), s)
    corner = int(np.flatnonzero(s == path.kinks[0])[0])
    assert constraints.sd_max[corner] == 0.0
    assert constraints.a_left[corner][:2] == pytest.approx([2.0, 0.0])  # coming along joint 0
    assert constraints.a[corner][:2] == pytest.approx([0.0, 2.0])  # leaving along joint 1
