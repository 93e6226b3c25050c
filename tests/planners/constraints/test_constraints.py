"""PathConstraints: the rows reproduce the robot's torques and accelerations exactly."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.paths import SplinePath, StopAndGoPath
from toptraj.planners.paths.grid import path_grid

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


def test_rows_of_finite_limits_only_in_chunks(monkeypatch):
    """Rows exist only for finite limits (acceleration rows first, then torque), sd_max and its
    binding joint follow min_j v_j / |q'_j| (a joint at rest or without a limit never binds), and
    computing the torque rows a few points at a time gives the same numbers."""
    import dataclasses

    from toptraj.planners.constraints import path_constraints as module

    robot = robots.load("ur5")
    waypoints = RNG.uniform(-1, 1, (4, 6))
    waypoints[:, 3] = 0.4  # joint 3 never moves: q'_3 = 0
    path = SplinePath(waypoints)
    limits = dataclasses.replace(
        robot.limits,
        velocity=np.where(np.arange(6) == 1, np.inf, robot.limits.velocity),
        acceleration=np.where(np.arange(6) == 2, np.inf, robot.limits.acceleration),
        torque=np.where(np.arange(6) == 0, np.inf, robot.limits.torque),
    )
    s = path_grid(path, 50)
    kinds = ("velocity", "acceleration", "torque")
    whole = build_path_constraints(path, robot, limits, kinds, s)
    assert whole.rows == tuple(("acceleration", j) for j in (0, 1, 3, 4, 5)) + tuple(("torque", j) for j in range(1, 6))
    points = path.evaluate(s)
    with np.errstate(divide="ignore"):
        per_joint = limits.velocity / np.abs(points.dq)
    assert np.array_equal(whole.sd_max, np.min(per_joint, axis=1))
    assert np.array_equal(whole.velocity_joint, np.argmin(per_joint, axis=1))
    assert not np.any(np.isin(whole.velocity_joint, (1, 3)))
    assert np.array_equal(whole.a[:, :5], points.dq[:, [0, 1, 3, 4, 5]])
    assert np.array_equal(whole.upper[0], np.concatenate([limits.acceleration[[0, 1, 3, 4, 5]], limits.torque[1:]]))
    assert np.array_equal(whole.lower, -whole.upper)
    # tau = a u + b x + c + d sd: g = RNEA(q, 0, 0), a = RNEA(q, 0, q') - g, b = RNEA(q, q', q'') - g
    zero = np.zeros_like(points.dq)
    g = robot.rnea(points.q, zero, zero)
    torque = (
        robot.rnea(points.q, zero, points.dq) - g,
        robot.rnea(points.q, points.dq, points.ddq) - g,
        g + robot.coulomb_friction * np.sign(points.dq),
        robot.viscous_friction * points.dq,
    )
    for mine, reference in zip((whole.a, whole.b, whole.c, whole.d), torque):
        assert mine[:, 5:] == pytest.approx(reference[:, 1:], rel=1e-12, abs=1e-12)
    monkeypatch.setattr(module, "CHUNK_POINTS", 7)
    chunked = build_path_constraints(path, robot, limits, kinds, s)
    for name in ("a", "b", "c", "d", "lower", "upper", "sd_max"):
        assert np.array_equal(getattr(chunked, name), getattr(whole, name)), name


@pytest.mark.parametrize("make", ["corners", "spline_off_grid_knot"])
def test_refined_constraints_know_their_smooth_points(make):
    """``with_points`` hands the refined grid the smooth points (``PathConstraints.smooth``) it
    derives from the coarse grid's: the same as computing them afresh, at corners (rows that
    differ from the two sides) and where a new point falls on a knot the grid did not hold."""
    from toptraj.planners.constraints.torque_interpolation import smooth_points

    robot = robots.load("ur5")
    kinds = ("velocity", "acceleration", "torque")
    if make == "corners":
        path = StopAndGoPath(np.array([[0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 0], [1, 1, 0, 0, 0, 0.0]]))
        s = path_grid(path, 20)
        extra = 0.5 * (s[:-1] + s[1:])[::3]
    else:
        path = SplinePath(RNG.uniform(-1, 1, (3, 6)))
        s = np.linspace(0.0, 1.0, 7)  # the inner knot is no grid point
        extra = np.array([0.1, path.knots[1], 0.9])
    constraints = build_path_constraints(path, robot, robot.limits, kinds, s)
    refined = constraints.with_points(extra)
    np.testing.assert_array_equal(refined.smooth, smooth_points(refined))
    assert not refined.smooth.flags.writeable
    if make == "spline_off_grid_knot":
        assert path.knots[1] not in s
        assert not refined.smooth[np.flatnonzero(refined.s == path.knots[1])[0]]
