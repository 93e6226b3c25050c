"""Kinematic conditioning against Angeles' problems 5.16 and 5.17, and the characteristic length
of the papers' two-link arms."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import minimize

from toptraj import robots
from toptraj.planners.kinematics.conditioning import frobenius_condition_number, task_jacobian
from toptraj.robots.catalog import robot_from_model

LINK = '<link name="{name}"><inertial><origin xyz="{com} 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'


def _planar_2r(a1: float, a2: float):
    """A planar 2R arm with link lengths a1, a2 (joint axes along z)."""
    urdf = f"""<robot name="planar">
      <link name="base"/>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
        <limit lower="-7" upper="7" effort="1" velocity="1"/></joint>
      {LINK.format(name="l1", com=a1 / 2)}
      <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="{a1} 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-7" upper="7" effort="1" velocity="1"/></joint>
      {LINK.format(name="l2", com=a2 / 2)}
      <joint name="tip_mount" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="{a2} 0 0"/></joint>
      <link name="tip"/>
    </robot>"""
    return robot_from_model("planar", pin.buildModelFromXML(urdf), "upload", "tip")


def _orthogonal_3r(length: float):
    """Angeles 5.17: e1 vertical, e2 = e3 horizontal, two links of equal length."""
    urdf = f"""<robot name="orthogonal">
      <link name="base"/>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l0"/><axis xyz="0 0 1"/>
        <limit lower="-7" upper="7" effort="1" velocity="1"/></joint>
      {LINK.format(name="l0", com=0)}
      <joint name="j2" type="revolute"><parent link="l0"/><child link="l1"/><axis xyz="0 -1 0"/>
        <limit lower="-7" upper="7" effort="1" velocity="1"/></joint>
      {LINK.format(name="l1", com=length / 2)}
      <joint name="j3" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="{length} 0 0"/><axis xyz="0 -1 0"/>
        <limit lower="-7" upper="7" effort="1" velocity="1"/></joint>
      {LINK.format(name="l2", com=length / 2)}
      <joint name="tip_mount" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="{length} 0 0"/></joint>
      <link name="tip"/>
    </robot>"""
    return robot_from_model("orthogonal", pin.buildModelFromXML(urdf), "upload", "tip")


def _kappa(robot, q):
    return frobenius_condition_number(task_jacobian(robot, np.asarray(q, dtype=float), robot.frame_id("tip"), 1.0))


def test_angeles_5_16_closed_form():
    """kappa_F = (1 + 2 r^2 + 2 r c2) / (2 r s2) for the 2R arm, r = a2 / a1."""
    for r in (0.3, np.sqrt(2) / 2, 1.0, 1.7):
        arm = _planar_2r(1.0, r)
        for theta2 in (0.4, 1.3, 2.2, -2.5):
            expected = (1 + 2 * r**2 + 2 * r * np.cos(theta2)) / (2 * r * abs(np.sin(theta2)))
            assert _kappa(arm, [0.7, theta2]) == pytest.approx(expected, rel=1e-12)


def test_angeles_5_16_minimum_is_isotropic():
    """Minimum kappa_F = 1 at r = sqrt(2) / 2 and theta2 = +-3 pi / 4."""
    arm = _planar_2r(1.0, np.sqrt(2) / 2)
    for theta2 in (3 * np.pi / 4, -3 * np.pi / 4):
        assert _kappa(arm, [0.2, theta2]) == pytest.approx(1.0, abs=1e-12)
    best = minimize(
        lambda x: _kappa(_planar_2r(1.0, x[0]), [0.0, x[1]]),
        [0.5, 2.0],
        method="Nelder-Mead",
        options={"xatol": 1e-10, "fatol": 1e-14, "maxiter": 4000},
    )
    assert best.fun == pytest.approx(1.0, abs=1e-9)
    assert best.x[0] == pytest.approx(np.sqrt(2) / 2, abs=1e-5)
    assert abs(best.x[1]) == pytest.approx(3 * np.pi / 4, abs=1e-4)


def test_angeles_5_17_orthogonal_3r():
    """kappa_m = 1.0798 at theta2 = -65.34 deg, theta3 = 130.68 deg; KCI = 92.61 %."""
    arm = _orthogonal_3r(0.5)
    best = minimize(lambda x: _kappa(arm, [0.0, x[0], x[1]]), np.radians([-60.0, 120.0]), method="Nelder-Mead",
                    options={"xatol": 1e-10, "fatol": 1e-14, "maxiter": 4000})
    assert best.fun == pytest.approx(1.0798, abs=5e-5)
    assert np.degrees(best.x) == pytest.approx([-65.34, 130.68], abs=0.01)
    assert 100 / best.fun == pytest.approx(92.61, abs=0.005)
    # theta1 does not change the condition number.
    assert _kappa(arm, [1.1, *best.x]) == pytest.approx(best.fun, rel=1e-12)


def test_singular_configuration_is_infinite():
    arm = _planar_2r(1.0, 0.5)
    assert _kappa(arm, [0.3, 0.0]) == np.inf


@pytest.mark.parametrize("shape", [(6, 6), (6, 7), (3, 2), (3, 3), (6, 4), (6, 1)])
def test_the_gram_matrix_route_equals_the_singular_values(shape):
    """kappa_F from tr G tr G^-1 equals the value from the singular values, to 1e-9 relative,
    on random matrices from isotropic to rank-deficient (those take the singular values)."""
    rng = np.random.default_rng(sum(shape))
    m, n = shape
    stack = []
    for exponent in np.linspace(0.0, 14.0, 60):  # condition numbers 1 to 1e14, then rank-deficient
        u, _ = np.linalg.qr(rng.normal(size=(m, m)))
        v, _ = np.linalg.qr(rng.normal(size=(n, n)))
        sigma = np.logspace(0.0, -exponent, min(m, n))
        stack.append((u[:, : len(sigma)] * sigma) @ v[:, : len(sigma)].T)
    stack.append(np.zeros((m, n)))
    stack = np.array(stack)
    values = np.linalg.svd(stack, compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        expected = np.sqrt(np.sum(values**2, axis=1) * np.sum(values**-2.0, axis=1)) / values.shape[1]
    expected[values.min(axis=1) <= 1e-12 * np.maximum(values.max(axis=1), 1e-300)] = np.inf
    kappa = frobenius_condition_number(stack)
    finite = np.isfinite(expected)
    assert np.array_equal(np.isfinite(kappa), finite)
    assert kappa[finite] == pytest.approx(expected[finite], rel=1e-9)
    assert frobenius_condition_number(stack[3]) == pytest.approx(expected[3], rel=1e-9)


@pytest.mark.parametrize(("name", "reach"), [("geering_2r", 0.4 + 0.25), ("yamamoto_2r", 0.2 + 0.2)])
def test_the_characteristic_length_is_the_reach_at_the_neutral_posture(name, reach):
    """L of the two-link arms of the papers, stretched out at q = 0: the sum of their link
    lengths (the URDFs' joint and tip offsets), the same at every call."""
    from toptraj.planners.kinematics.conditioning import characteristic_length, conditioning_along

    robot = robots.load(name)
    assert robot.neutral_reach == pytest.approx(reach, abs=1e-15)
    assert characteristic_length(robot) == robot.neutral_reach
    assert conditioning_along(robot, np.array([[0.3, 0.5], [0.1, -0.4]]), np.arange(2))[2] == pytest.approx(reach, abs=1e-15)
