"""The solvers with absolute tolerances (toppra's LP, min_cost's Clarabel) at the small end of
the limits' range: an acceleration limit of 1e-6 rad/s^2, or a torque limit of 1e-6 N m on one
joint next to 25 N m on the other, makes a slow motion, not an infeasible one.

Checked against scaling laws, independent of any solver. When acceleration limits alone bind
(the same a on every joint), x = sd^2 scales with a, so the time-optimal duration on the same
grid is T(a) = T(1) / sqrt(a); on the ur5 spline below neither its velocity nor its torque
limits bind at a <= 1 rad/s^2 (the motion at a = 1 stays under 1.1 rad/s, a third of the
velocity limits). On the Geering arm (no gravity in its plane, no velocity or acceleration
limits) with the elbow's torque limit tau_2 alone binding, T scales as 1 / sqrt(tau_2)."""

from __future__ import annotations

import numpy as np
import pytest

import robots
from planners import Timing, WaypointPath, plan

UR5 = robots.load("ur5")
GEERING = robots.load("geering_2r")
SPLINE = WaypointPath(
    np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]])
)
LINE = WaypointPath(np.array([[0.0, 0.0], [0.5, 0.3]]))
CONSTRAINTS = ("velocity", "acceleration", "torque")


def _duration(robot, path, method: str, overrides: dict) -> float:
    return plan(robot, path, Timing(method=method, constraints=CONSTRAINTS, limit_overrides=overrides), dt=10.0).duration


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
def test_a_tiny_acceleration_limit_is_a_slow_motion(method):
    """T(a) sqrt(a) = T(1) at a = 1e-6 rad/s^2 (2,961 s), to the solver's tolerance."""
    tiny = _duration(UR5, SPLINE, method, {"acceleration": [1e-6] * 6})
    assert tiny * 1e-3 == pytest.approx(_duration(UR5, SPLINE, method, {"acceleration": [1.0] * 6}), rel=1e-6)


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
def test_torque_limits_eight_orders_apart_are_a_slow_motion(method):
    """T(tau_2 = 1e-6) = 10 T(tau_2 = 1e-4) with tau_1 = 25 N m (2,289 s), to the solver's
    tolerance: the rows of the two joints differ by 2.5e7 in scale."""
    tiny = _duration(GEERING, LINE, method, {"torque": [25.0, 1e-6]})
    assert tiny == pytest.approx(10.0 * _duration(GEERING, LINE, method, {"torque": [25.0, 1e-4]}), rel=1e-6)
