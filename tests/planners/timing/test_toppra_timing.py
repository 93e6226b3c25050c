"""TOPP-RA on PathConstraints, against closed-form time-optimal answers."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, WaypointPath, build_problem, plan

UR5 = robots.load("ur5")


def _single_joint_move(length):
    start = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])
    goal = start.copy()
    goal[0] += length
    return WaypointPath(np.array([start, goal]))


@pytest.mark.parametrize("length", [0.3, 1.0, 2.5])
def test_acceleration_only_bang_bang(length):
    """One joint, |qdd| <= a: T = 2 sqrt(L / a)."""
    accel = UR5.limits.acceleration[0]
    result = plan(build_problem(UR5, _single_joint_move(length), METHODS["phase_plane"], limits=LimitRequest(kinds=("acceleration",))))
    assert result.duration == pytest.approx(2 * np.sqrt(length / accel), rel=1e-6)


@pytest.mark.parametrize("grid_points, tolerance", [(None, 2e-4), (3000, 1e-6)])
def test_velocity_and_acceleration_long_move(grid_points, tolerance):
    """One joint, |qd| <= v, |qdd| <= a, L > v^2 / a: T = L / v + v / a. The switch from
    acceleration to cruise falls inside a grid interval, so the grid answer is longer by O(ds^2)."""
    length = 3.0
    v, a = 1.0, 4.0
    timing = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [v] * 6, "acceleration": [a] * 6}), grid=grid_points)
    result = plan(build_problem(UR5, _single_joint_move(length), **timing))
    assert result.duration >= length / v + v / a
    assert result.duration == pytest.approx(length / v + v / a, rel=tolerance)


def test_limit_scales_slow_the_motion_as_expected():
    """Acceleration-limited motion: a quarter of the acceleration doubles the time."""
    base = plan(build_problem(UR5, _single_joint_move(1.0), METHODS["phase_plane"], limits=LimitRequest(kinds=("acceleration",))))
    slow = plan(build_problem(UR5, _single_joint_move(1.0), METHODS["phase_plane"], limits=LimitRequest(kinds=("acceleration",), scales={"acceleration": 0.25})))
    assert slow.duration == pytest.approx(2 * base.duration, rel=1e-6)
