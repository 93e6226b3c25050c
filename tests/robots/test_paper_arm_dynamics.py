"""The bundled paper arms: Pinocchio's RNEA on the URDF equals the papers' equations."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots

RNG = np.random.default_rng(20240531)


def _rnea(robot, q, v, a):
    return pin.rnea(robot.model, robot.model.createData(), robot.configuration(q), v, a)


def _mass_matrix(robot, q):
    matrix = pin.crba(robot.model, robot.model.createData(), robot.configuration(q))
    return np.triu(matrix) + np.triu(matrix, 1).T


# Jeong & Lee section 4.1 constants.
J1, J2, J3 = 1.6, 0.43, 0.01
L1, L2, R2, M2, M3 = 0.4, 0.25, 0.125, 15.0, 6.0
J4 = J2 + L2**2 * M3
J5 = J1 + L1**2 * (M2 + M3)
J6 = L1 * (R2 * M2 + L2 * M3)
J7 = J3 + J4


def geering_torques(q, v, a):
    """Inverse dynamics of the horizontal arm, derived from first principles.

    The printed (4.8)/(4.10) are garbled by the scan (sin(x2) for sin(x3), J2 for J7, ...);
    the switching functions (4.16)/(4.17) fix the inertia matrix unambiguously:
    M = [[J5 + J7 + 2 J6 cos psi, J7 + J6 cos psi], [J7 + J6 cos psi, J7]], whose inverse has
    the numerators 0.815, -(0.815 + 1.35 cos), 5.775 + 2.7 cos of (4.16)/(4.17) over
    det M = J5 J7 - J6^2 cos^2 psi. The velocity terms follow from M by the Christoffel symbols.
    """
    phi, psi = q
    dphi, dpsi = v
    c, s = np.cos(psi), np.sin(psi)
    mass = np.array([[J5 + J7 + 2 * J6 * c, J7 + J6 * c], [J7 + J6 * c, J7]])
    velocity_terms = J6 * s * np.array([-(2 * dphi * dpsi + dpsi**2), dphi**2])
    return mass @ a + velocity_terms


def yamamoto_torques(q, v, a, inertia=4.167e-3, mass=1.0, half=0.1, gravity=9.81):
    """Yamamoto, Marushima & Mohri eq. (31), as printed."""
    t1, t2 = q
    d1, d2 = v
    I, m, l, g = inertia, mass, half, gravity
    u1 = (
        (2 * I + 2 * m * l**2 * (3 + 2 * np.cos(t2))) * a[0]
        + (I + m * l**2 * (1 + 2 * np.cos(t2))) * a[1]
        - 2 * m * l**2 * np.sin(t2) * (2 * d1 * d2 + d2**2)
        - m * g * l * (3 * np.sin(t1) + np.sin(t1 + t2))
    )
    u2 = (
        (I + m * l**2 * (1 + 2 * np.cos(t2))) * a[0]
        + (I + m * l**2) * a[1]
        + 2 * m * l**2 * np.sin(t2) * d1**2
        - m * g * l * np.sin(t1 + t2)
    )
    return np.array([u1, u2])


@pytest.mark.parametrize(
    "name, equations", [("geering_2r", geering_torques), ("yamamoto_2r", yamamoto_torques)]
)
def test_rnea_matches_paper_equations(name, equations):
    robot = robots.load(name)
    for _ in range(200):
        q = RNG.uniform(-2 * np.pi, 2 * np.pi, 2)
        v = RNG.uniform(-10, 10, 2)
        a = RNG.uniform(-50, 50, 2)
        assert np.max(np.abs(_rnea(robot, q, v, a) - equations(q, v, a))) <= 1e-9


def test_geering_determinant_is_the_switching_function_denominator():
    robot = robots.load("geering_2r")
    for psi in RNG.uniform(-2 * np.pi, 2 * np.pi, 50):
        mass = _mass_matrix(robot, np.array([0.3, psi]))
        assert np.linalg.det(mass) == pytest.approx(4.0424 - 1.8225 * np.cos(psi) ** 2, abs=1e-12)
        # Numerators of h1 (4.16) and h2 (4.17): det M times the inverse inertia matrix.
        adjugate = np.linalg.inv(mass) * np.linalg.det(mass)
        c = np.cos(psi)
        assert adjugate == pytest.approx(np.array([[0.815, -(0.815 + 1.35 * c)], [-(0.815 + 1.35 * c), 5.775 + 2.7 * c]]), abs=1e-12)


def test_geering_has_no_gravity_torque_and_a_continuous_elbow():
    robot = robots.load("geering_2r")
    for q in RNG.uniform(-6, 6, (20, 2)):
        assert np.max(np.abs(_rnea(robot, q, np.zeros(2), np.zeros(2)))) <= 1e-12
    assert robot.continuous.tolist() == [False, True]
    assert robot.limits.torque.tolist() == [25.0, 9.0]
    assert robot.limits.position_lower[1] == -np.inf
    # psi = -2 pi is the same pose as psi = 0 but a distinct coordinate.
    assert robot.configuration(np.array([0.0, -2 * np.pi])) == pytest.approx(robot.configuration(np.zeros(2)), abs=1e-12)


def test_yamamoto_limits_and_upright_zero():
    robot = robots.load("yamamoto_2r")
    assert robot.limits.torque.tolist() == [10.0, 5.0]
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(np.zeros(2)))
    tip = data.oMf[robot.frame_id(robot.end_effector)].translation
    assert tip == pytest.approx([0.0, 0.0, 0.4], abs=1e-12)
