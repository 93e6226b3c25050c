"""The robot catalog: example-robot-data arms, limits from the data file, request overrides."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.robots.catalog import EXAMPLE_ARMS


@pytest.mark.parametrize("name", list(robots.catalog_names()))
def test_every_catalog_arm_loads_with_complete_limits(name):
    robot = robots.load(name)
    assert robot.model.nv == robot.dof == len(robot.joint_names)
    limits = robot.limits
    for kind in ("velocity", "acceleration", "jerk", "torque"):
        values = getattr(limits, kind)
        assert values.shape == (robot.dof,)
        assert np.all(values > 0)
    assert np.all(limits.position_lower < limits.position_upper)
    assert robot.model.existFrame(robot.end_effector)


def test_named_arms():
    assert robots.load("ur5").dof == 6
    assert robots.load("ur10").dof == 6
    panda = robots.load("panda")
    assert panda.dof == 7
    assert not any("finger" in joint for joint in panda.joint_names)
    assert panda.limits.acceleration.tolist() == [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0]
    assert robots.load("ur5").source == "example-robot-data"
    assert set(EXAMPLE_ARMS) <= set(robots.catalog_names())


def test_default_rule_for_arms_without_entry():
    xarm = robots.load("xarm7")
    assert xarm.limits.acceleration == pytest.approx(xarm.limits.velocity / 0.2)
    assert xarm.limits.jerk == pytest.approx(xarm.limits.acceleration / 0.05)


def test_unknown_robot():
    with pytest.raises(robots.UnknownRobot, match="no robot named 'nope'"):
        robots.load("nope")


def test_request_overrides_and_scales():
    limits = robots.load("ur5").limits
    changed = limits.with_request({"velocity": [1.0] * 6}, {"torque": 0.5, "acceleration": None})
    assert changed.velocity.tolist() == [1.0] * 6
    assert changed.torque == pytest.approx(limits.torque * 0.5)
    assert changed.acceleration.tolist() == limits.acceleration.tolist()
    with pytest.raises(robots.InvalidLimits) as refused:
        limits.with_request({"velocity": [1.0, 2.0]})
    assert (refused.value.field, refused.value.given, refused.value.expected) == ("limits.velocity", 2, 6)
    with pytest.raises(robots.InvalidLimits) as refused:
        limits.with_request({"velocity": [1.0, 0.0, 1, 1, 1, 1]})
    assert (refused.value.field, refused.value.value, refused.value.rule) == ("limits.velocity[1]", 0.0, "limit_not_positive")
    with pytest.raises(robots.InvalidLimits) as refused:
        limits.with_request(None, {"torque": -1.0})
    assert (refused.value.field, refused.value.value, refused.value.rule) == ("limits.torque_scale", -1.0, "scale_not_positive")


def test_continuous_joints_map_to_cos_sin():
    kinova = robots.load("kinova")
    assert kinova.continuous.any()
    q = np.linspace(-4, 4, kinova.dof)
    configuration = kinova.configuration(q)
    assert configuration.shape == (kinova.model.nq,)
    joint = kinova.model.joints[1]
    assert configuration[joint.idx_q : joint.idx_q + 2] == pytest.approx([np.cos(q[0]), np.sin(q[0])])
