"""Holding still beyond the torque limits: the facts a refusal carries (every stretch no motion
can follow, the loads at rest against the limits, the scale and limits that hold the path),
checked against an independent RNEA at rest."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners import LimitRequest, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.timing import METHODS

START, GOAL = [0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]


def _refusal(scale: float) -> InfeasiblePath:
    robot = robots.load("ur5")
    problem = build_problem(
        robot, WaypointPath(np.array([START, GOAL], dtype=float)), METHODS["phase_plane"], limits=LimitRequest(scales={"torque": scale})
    )
    with pytest.raises(InfeasiblePath) as caught:
        plan(problem)
    return caught.value


def _gravity(q) -> np.ndarray:
    robot = robots.load("ur5")
    return pin.rnea(robot.model, robot.model.createData(), np.array(q, dtype=float), np.zeros(6), np.zeros(6))


def test_the_refusal_carries_every_load_at_rest_and_the_remedy():
    error = _refusal(0.2)
    assert error.rule == "not_even_at_rest" and error.limit == "torque"
    [stretch] = error.stretches
    assert 0.0 < stretch.start < 1.0 and stretch.end == 1.0
    goal, start = _gravity(GOAL), _gravity(START)
    assert (stretch.worst.joint, stretch.worst.s) == ("shoulder_lift_joint", 1.0)
    assert stretch.worst.torque == pytest.approx(abs(goal[1]), rel=1e-9) and stretch.worst.limit == pytest.approx(30.0)
    [end] = error.ends  # the start, outside the stretch, where a motion from rest holds still
    assert (end.s, end.joint) == (0.0, "shoulder_lift_joint") and end.torque == pytest.approx(abs(start[1]), rel=1e-9)
    assert error.ratio == pytest.approx(abs(goal[1]) / 30.0, rel=1e-9)
    assert [load.joint for _, load in error.joints] == ["shoulder_lift_joint"]
    assert error.asked_scale == 0.2
    assert 0.2 * error.ratio < error.torque_scale <= 0.2 * error.ratio * 1.001 + 1e-3
    [(joint, limit, unit)] = error.torque_limits
    assert (joint, unit) == ("shoulder_lift_joint", "N m") and 150.0 * error.ratio < limit <= 150.0 * error.ratio * 1.001 + 1.0


def test_a_joint_holding_no_gravity_is_never_blamed():
    """The base's axis is vertical: RNEA at rest gives it no torque anywhere along the path."""
    error = _refusal(0.1)
    blamed = {error.joint, *(item.worst.joint for item in error.stretches), *(load.joint for _, load in error.joints)}
    assert "shoulder_pan_joint" not in blamed
    assert blamed == {"shoulder_lift_joint", "elbow_joint"}
    for s in np.linspace(0.0, 1.0, 11):
        assert abs(_gravity(np.add(START, s * np.subtract(GOAL, START)))[0]) < 1e-9
