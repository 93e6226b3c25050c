"""A duration given too short for its time law: the error states the shortest that holds the
limits, found by planning the same law without a duration (``toptraj.planners.runner.duration``)."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import LimitRequest, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath, LimitExceeded
from toptraj.planners.runner.duration import rounded_up
from toptraj.planners.timing import METHODS

START, GOAL = [0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]


def test_rounded_up_keeps_three_digits_and_never_rounds_down():
    assert rounded_up(0.7598356) == 0.76
    assert rounded_up(0.76) == 0.76
    assert rounded_up(1.2301) == 1.24
    assert rounded_up(12.349) == 12.4
    assert rounded_up(0.0012345) == 0.00124


def test_a_quintic_too_short_names_its_shortest_duration():
    """On a straight joint path q0 + s (q1 - q0), the quintic s(t) = 10 u^3 - 15 u^4 + 6 u^5
    (u = t / T) peaks at s'' = 10 / sqrt(3) / T^2 and s' = 1.875 / T (Biagiotti & Melchiorri
    2008, §2.1.6); the shortest T holds every joint's velocity and acceleration limit (the
    torques of this motion stay far within theirs)."""
    robot = robots.load("ur5")
    step = np.abs(np.subtract(GOAL, START))
    expected = max(
        np.sqrt(10 / np.sqrt(3) * step / robot.limits.acceleration).max(), (1.875 * step / robot.limits.velocity).max()
    )
    problem = build_problem(robot, WaypointPath(np.array([START, GOAL], dtype=float)), METHODS["quintic"], duration=0.1)
    with pytest.raises(LimitExceeded) as caught:
        plan(problem)
    error = caught.value
    assert (error.rule, error.field, error.value, error.limit, error.joint) == (
        "duration_too_short", "duration", 0.1, "acceleration", "shoulder_pan_joint",
    )
    assert error.shortest == pytest.approx(expected, rel=2e-3)
    assert error.exact and error.stated == rounded_up(error.shortest) == 0.76
    assert "the shortest is 0.76 s" in error.detail
    # The duration stated holds the limits.
    assert plan(build_problem(robot, WaypointPath(np.array([START, GOAL], dtype=float)), METHODS["quintic"], duration=error.stated)).duration == 0.76


def test_a_limit_broken_whatever_the_duration_keeps_its_own_error():
    """With the torque limits below gravity's hold at the start, no duration helps: the error is
    not about the duration."""
    robot = robots.load("ur5")
    problem = build_problem(
        robot, WaypointPath(np.array([START, GOAL], dtype=float)), METHODS["quintic"], duration=5.0,
        limits=LimitRequest(scales={"torque": 0.1}),
    )
    with pytest.raises(InfeasiblePath) as caught:
        plan(problem)
    assert getattr(caught.value, "rule", None) != "duration_too_short"
