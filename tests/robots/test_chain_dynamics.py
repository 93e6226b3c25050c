"""The compiled inverse dynamics (``toptraj.robots.chain_dynamics``, behind ``Robot.rnea``) against
Pinocchio's ``rnea``, one state at a time."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from tests.paths import DATA
from tests.planners.kinematics.test_frame_jacobians import SKEWED
from toptraj import robots
from toptraj.robots.catalog import robot_from_model


def _lopsided(model: pin.Model, seed: int) -> pin.Model:
    """``model`` with every body's centre of mass off its joint's origin, a full rotational
    inertia (products of inertia too) and rotor inertia on every coordinate."""
    model = model.copy()
    rng = np.random.default_rng(seed)
    for index in range(1, model.njoints):
        root = rng.uniform(-0.2, 0.2, (3, 3))
        model.inertias[index] = pin.Inertia(rng.uniform(0.5, 3.0), rng.uniform(-0.3, 0.3, 3), root @ root.T + 0.01 * np.eye(3))
    model.armature = rng.uniform(0.0, 0.5, model.nv)
    return model


def _robots():
    yield from (robots.load(name) for name in robots.catalog_names())
    yield robot_from_model("lift_rp", pin.buildModelFromXML((DATA / "lift_rp.urdf").read_text()), "upload", "hand")
    yield robot_from_model("skewed", pin.buildModelFromXML(SKEWED), "upload", "tip")
    yield robot_from_model("skewed_lopsided", _lopsided(pin.buildModelFromXML(SKEWED), 11), "upload", "tip")
    yield robot_from_model("ur5_lopsided", _lopsided(robots.load("ur5").model, 12), "upload", "tool0")


def _pinocchio(robot, q, qd, qdd) -> np.ndarray:
    data = robot.model.createData()
    return np.array([pin.rnea(robot.model, data, *state) for state in zip(robot.configuration(q), qd, qdd)])


@pytest.mark.parametrize("robot", list(_robots()), ids=lambda robot: robot.name)
def test_every_arm_has_pinocchios_inverse_dynamics(robot):
    assert robot.chain is not None
    rng = np.random.default_rng(3)
    q = rng.uniform(-2.5, 2.5, (20, robot.dof))
    qd = rng.uniform(-2.0, 2.0, (3, 20, robot.dof))
    qdd = rng.uniform(-5.0, 5.0, (3, 20, robot.dof))
    qd[0] = 0.0  # the sets the constraint build asks for: (q, 0, 0), (q, 0, q'), (q, q', q'')
    qdd[0] = 0.0
    qd[1] = 0.0
    tau = robot.rnea_sets(q, qd, qdd)
    assert tau.shape == (3, 20, robot.dof)
    for m in range(3):
        expected = _pinocchio(robot, q, qd[m], qdd[m])
        scale = max(1.0, float(np.abs(expected).max()))
        np.testing.assert_allclose(tau[m], expected, rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(robot.rnea(q, qd[m], qdd[m]), expected, rtol=0, atol=1e-13 * scale)



@pytest.mark.parametrize("robot", list(_robots()), ids=lambda robot: robot.name)
def test_sets_at_rest_take_the_shorter_pass_with_the_same_numbers(robot):
    """Leading sets without velocity skip the velocity terms, which are zero: their torques
    equal, bit for bit, those of the same sets behind a moving one (which take the full pass),
    and Pinocchio's."""
    rng = np.random.default_rng(5)
    q = rng.uniform(-2.5, 2.5, (15, robot.dof))
    qd = rng.uniform(-2.0, 2.0, (3, 15, robot.dof))
    qdd = rng.uniform(-5.0, 5.0, (3, 15, robot.dof))
    qd[[0, 1]] = 0.0
    leading = robot.rnea_sets(q, qd, qdd)
    behind = robot.rnea_sets(q, qd[[2, 0, 1]], qdd[[2, 0, 1]])
    np.testing.assert_array_equal(leading, behind[[1, 2, 0]])
    for m in range(3):
        expected = _pinocchio(robot, q, qd[m], qdd[m])
        np.testing.assert_allclose(leading[m], expected, rtol=0, atol=1e-13 * max(1.0, float(np.abs(expected).max())))


def test_the_lopsided_arm_feels_what_the_test_changed():
    """The lopsided model's torques differ from the plain one's (the inertias and the armature
    reach the compiled pass, not only Pinocchio)."""
    plain = robot_from_model("skewed", pin.buildModelFromXML(SKEWED), "upload", "tip")
    lopsided = robot_from_model("skewed_lopsided", _lopsided(pin.buildModelFromXML(SKEWED), 11), "upload", "tip")
    q, qd, qdd = np.full((1, 4), 0.3), np.full((1, 4), 0.5), np.full((1, 4), 1.0)
    assert np.abs(lopsided.rnea(q, qd, qdd) - plain.rnea(q, qd, qdd)).min() > 1e-3


def test_continuous_joints_take_their_angle():
    """A continuous joint is one angle in toptraj's coordinates and a (cos, sin) pair in
    Pinocchio's: the compiled pass reads the angle, two turns apart give the same torques."""
    robot = robot_from_model("skewed", pin.buildModelFromXML(SKEWED), "upload", "tip")
    assert robot.continuous.tolist() == [False, False, True, False]
    rng = np.random.default_rng(4)
    q, qd, qdd = rng.uniform(-1.0, 1.0, (3, 5, robot.dof))
    turned = q.copy()
    turned[:, 2] += 4.0 * np.pi
    np.testing.assert_allclose(robot.rnea(turned, qd, qdd), robot.rnea(q, qd, qdd), rtol=0, atol=1e-12)


def test_an_arm_without_a_chain_takes_pinocchios_batch():
    """A ball joint is none of the chain's: the torques come from Pinocchio's batched RNEA, bit
    for bit what ``pin.rnea`` gives state by state, for one set and for several."""
    model = pin.Model()
    ball = model.addJoint(0, pin.JointModelSphericalZYX(), pin.SE3.Identity(), "ball")
    model.appendBodyToJoint(ball, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3(np.eye(3), np.array([0.0, 0.1, 0.2])))
    elbow = model.addJoint(ball, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.4])), "elbow")
    model.appendBodyToJoint(elbow, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3(np.eye(3), np.array([0.2, 0.0, 0.0])))
    model.addFrame(pin.Frame("tip", elbow, 0, pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0])), pin.FrameType.OP_FRAME))
    free = np.full(model.nv, np.inf)
    robot = robots.Robot.from_model("ball", model, "upload", "tip", robots.JointLimits(-free, free, free, free, free, free))
    assert robot.chain is None
    rng = np.random.default_rng(6)
    q = rng.uniform(-1.0, 1.0, (7, robot.dof))
    qd, qdd = rng.uniform(-1.0, 1.0, (2, 2, 7, robot.dof))
    tau = robot.rnea_sets(q, qd, qdd)
    for m in range(2):
        np.testing.assert_array_equal(tau[m], _pinocchio(robot, q, qd[m], qdd[m]))
    np.testing.assert_array_equal(robot.rnea(q, qd[1], qdd[1]), tau[1])


def test_no_states_no_torques():
    robot = robots.load("ur5")
    assert robot.rnea(np.empty((0, 6)), np.empty((0, 6)), np.empty((0, 6))).shape == (0, 6)
    assert robot.rnea_sets(np.empty((0, 6)), np.empty((3, 0, 6)), np.empty((3, 0, 6))).shape == (3, 0, 6)
