"""The solvers with absolute tolerances (toppra's LP, min_cost's Clarabel) at the small end of
the limits' range, and below it through a scale factor: an acceleration limit of 1e-6 rad/s^2,
or 1e-9 after ``acceleration_scale``, makes a slow motion, not an infeasible one.

Checked against a scaling law, independent of any solver: when acceleration limits alone bind
(the same a on every joint), x = sd^2 scales with a, so the time-optimal duration on the same
grid is T(a) = T(1) / sqrt(a). On the spline below neither the velocity nor the torque limits
of the ur5 bind at a <= 1 rad/s^2 (its velocity limits are 3.15 rad/s, and the motion at a = 1
stays under 1.1 rad/s)."""

from __future__ import annotations

import numpy as np
import pytest

import robots
from planners import Timing, WaypointPath, plan

UR5 = robots.load("ur5")
SPLINE = WaypointPath(
    np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]])
)
CONSTRAINTS = ("velocity", "acceleration", "torque")


def _duration(method: str, acceleration: float, scale: float | None) -> float:
    timing = Timing(
        method=method,
        constraints=CONSTRAINTS,
        limit_overrides={"acceleration": [acceleration] * 6},
        limit_scales={"acceleration": scale},
    )
    return plan(UR5, SPLINE, timing, dt=10.0).duration


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
@pytest.mark.parametrize("acceleration, scale", [(1e-6, None), (1e-6, 1e-3)])
def test_tiny_acceleration_is_a_slow_motion(method, acceleration, scale):
    """T(a) sqrt(a) = T(1), to the solver's relative tolerance (1e-6), at a = 1e-6 and 1e-9."""
    a = acceleration * (scale or 1.0)
    assert _duration(method, acceleration, scale) * np.sqrt(a) == pytest.approx(_duration(method, 1.0, None), rel=1e-6)
