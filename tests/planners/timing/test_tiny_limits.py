"""The solvers with absolute tolerances (toppra's LP, min_cost's Clarabel) at the small end of
the limits' range: an acceleration limit of 1e-6 rad/s^2, or limits of 1e-6 on some joints
next to 1e3 (velocity) and 1e5 (acceleration) on the others, make a slow motion, not an
infeasible one.

Checked against scaling laws, independent of any solver. When acceleration limits alone bind
(the same a on every joint), x = sd^2 scales with a, so the time-optimal duration on the same
grid is T(a) = T(1) / sqrt(a); on the ur5 spline below neither its velocity nor its torque
limits bind at a <= 1 rad/s^2 (the motion at a = 1 stays under 1.1 rad/s, a third of the
velocity limits). Limits eight to eleven orders apart have no such law: the phase-plane method,
whose tolerances are relative, is the reference there, within its own stated gap."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan

UR5 = robots.load("ur5")
SPLINE = WaypointPath(
    np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]])
)
CONSTRAINTS = ("velocity", "acceleration", "torque")


def _duration(robot, path, method: str, overrides: dict) -> float:
    return plan(build_problem(robot, path, METHODS[method], limits=LimitRequest(kinds=CONSTRAINTS, overrides=overrides), sampling=Sampling(dt=10.0))).duration


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
def test_a_tiny_acceleration_limit_is_a_slow_motion(method):
    """T(a) sqrt(a) = T(1) at a = 1e-6 rad/s^2 (2,961 s), to the solver's tolerance."""
    tiny = _duration(UR5, SPLINE, method, {"acceleration": [1e-6] * 6})
    assert tiny * 1e-3 == pytest.approx(_duration(UR5, SPLINE, method, {"acceleration": [1.0] * 6}), rel=1e-6)


@pytest.mark.parametrize("method", ["toppra", "min_cost"])
def test_limits_orders_apart_on_one_arm_are_a_slow_motion(method):
    """About 1.04e6 s; within 0.1 % of the phase-plane method's duration."""
    overrides = {"velocity": [1e3, 1e-6] * 3, "acceleration": [1e5, 1e-6] * 3}
    timing = dict(method=METHODS[method], limits=LimitRequest(kinds=CONSTRAINTS, overrides=overrides))
    reference = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=CONSTRAINTS, overrides=overrides))
    duration = plan(build_problem(UR5, SPLINE, **timing, sampling=Sampling(dt=10.0, max_samples=200_000))).duration
    assert duration == pytest.approx(plan(build_problem(UR5, SPLINE, **reference, sampling=Sampling(dt=10.0, max_samples=200_000))).duration, rel=1e-3)
