"""The compiled frame Jacobians (``toptraj.planners.kinematics.frame_jacobians``) against Pinocchio's
``computeFrameJacobian`` and ``getFrameVelocity``, in ``LOCAL_WORLD_ALIGNED``."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from tests.paths import DATA
from toptraj import robots
from toptraj.planners.constraints.tool_speed import frame_twists
from toptraj.planners.kinematics.frame_jacobians import frame_jacobians
from toptraj.robots.catalog import robot_from_model

LINK = '<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
#: Joint origins turned by rpy and axes along no coordinate axis: Pinocchio makes them its
#: unaligned revolute and prismatic joints, and a continuous joint its unbounded form.
SKEWED = f"""<robot name="skewed">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0.1 0 0.3" rpy="0.3 -0.2 0.7"/>
    <axis xyz="0.6 0 0.8"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  {LINK.format(name="l1")}
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/><origin xyz="0 0.2 0.1" rpy="-0.4 0.1 0"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  {LINK.format(name="l2")}
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/><origin xyz="0.3 0 0" rpy="0 0.5 0"/>
    <axis xyz="0 1 0"/><limit effort="10" velocity="1"/></joint>
  {LINK.format(name="l3")}
  <joint name="j4" type="revolute"><parent link="l1"/><child link="side"/><origin xyz="0 -0.2 0"/>
    <axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  {LINK.format(name="side")}
  <joint name="tip_mount" type="fixed"><parent link="l3"/><child link="tip"/><origin xyz="0.25 0.05 -0.1" rpy="0.2 0 0.3"/></joint>
  <link name="tip"/>
</robot>"""


def _pinocchio_jacobians(robot, frame_id: int, q: np.ndarray) -> np.ndarray:
    return np.array([
        np.reshape(pin.computeFrameJacobian(robot.model, robot.data, configuration, frame_id, pin.LOCAL_WORLD_ALIGNED), (6, robot.dof))
        for configuration in robot.configuration(q)
    ])


def _robots():
    yield from (robots.load(name) for name in robots.catalog_names())
    yield robot_from_model("lift_rp", pin.buildModelFromXML((DATA / "lift_rp.urdf").read_text()), "upload", "hand")
    yield robot_from_model("skewed", pin.buildModelFromXML(SKEWED), "upload", "tip")


@pytest.mark.parametrize("robot", list(_robots()), ids=lambda robot: robot.name)
def test_every_frame_jacobian_is_pinocchios(robot):
    assert robot.chain is not None  # every joint of these arms turns or slides about a fixed axis
    q = np.random.default_rng(7).uniform(-2.5, 2.5, (20, robot.dof))
    frames = [robot.frame_id(robot.end_effector), *range(1, len(robot.model.frames))]
    for frame_id in frames:
        np.testing.assert_allclose(frame_jacobians(robot, frame_id, q), _pinocchio_jacobians(robot, frame_id, q), rtol=0, atol=1e-12)


def test_a_frame_velocity_is_pinocchios():
    robot = robot_from_model("skewed", pin.buildModelFromXML(SKEWED), "upload", "tip")
    rng = np.random.default_rng(3)
    q, qd = rng.uniform(-2.0, 2.0, (30, robot.dof)), rng.uniform(-1.5, 1.5, (30, robot.dof))
    frame_id = robot.frame_id("tip")
    expected = []
    for configuration, velocity in zip(robot.configuration(q), qd):
        pin.forwardKinematics(robot.model, robot.data, configuration, velocity)
        expected.append(pin.getFrameVelocity(robot.model, robot.data, frame_id, pin.LOCAL_WORLD_ALIGNED).vector)
    np.testing.assert_allclose(frame_twists(robot, frame_id, q, qd), np.array(expected), rtol=0, atol=1e-12)


def test_an_arm_with_another_joint_is_left_to_pinocchio():
    """A ball joint in Euler angles is none of the chain's: the robot has no chain, and its
    Jacobians come from Pinocchio, one configuration at a time."""
    model = pin.Model()
    ball = model.addJoint(0, pin.JointModelSphericalZYX(), pin.SE3.Identity(), "ball")
    model.appendBodyToJoint(ball, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
    elbow = model.addJoint(ball, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.4])), "elbow")
    model.appendBodyToJoint(elbow, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
    tip = model.addFrame(pin.Frame("tip", elbow, 0, pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0])), pin.FrameType.OP_FRAME))
    free = np.full(model.nv, np.inf)
    limits = robots.JointLimits(-free, free, free, free, free, free)
    robot = robots.Robot.from_model("ball", model, "upload", "tip", limits)
    assert robot.chain is None
    q = np.random.default_rng(5).uniform(-1.0, 1.0, (6, robot.dof))
    jacobians = frame_jacobians(robot, tip, q)
    assert jacobians.shape == (6, 6, 4)
    np.testing.assert_array_equal(jacobians, _pinocchio_jacobians(robot, tip, q))
