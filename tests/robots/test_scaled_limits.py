"""A scale factor is one more source of a limit: the limit it makes lies in the range of its
kind, like an override, an upload's or a URDF's (``toptraj.robots.ranges``). Outside, a jerk limit of
1e-9 rad/s^3 (jerk_scale 1e-3 on 1e-6) made jerk_limited answer "the linear program is
infeasible" for a motion that exists; the request is refused before planning, with the factors
that are accepted, and following that advice plans."""

from __future__ import annotations

import re

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.errors import InvalidRequest
from toptraj.service.problems import detail

UR5 = robots.load("ur5")
TWO = WaypointPath(np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]]))
JERK_KINDS = ("velocity", "acceleration", "jerk")


@pytest.mark.parametrize(
    "method, kind, value, factor, low, high",
    [
        ("jerk_limited", "jerk", 1e-6, 1e-3, 1.0, 1e3),  # 1e-9 rad/s^3
        ("ruckig", "acceleration", 1e-6, 1e-3, 1.0, 1e3),  # 1e-9 rad/s^2
        ("ruckig", "velocity", 1e3, 2.0, 1e-3, 1.0),  # 2e3 rad/s
    ],
)
def test_a_scale_that_leaves_the_range_is_refused_with_followable_advice(method, kind, value, factor, low, high):
    constraints = JERK_KINDS
    overrides = {kind: [value] * UR5.dof}
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(UR5, TWO, METHODS[method], limits=LimitRequest(kinds=constraints, overrides=overrides, scales={kind: factor}), sampling=Sampling(dt=10.0)))
    error = refused.value
    assert (error.field, error.value, error.joint_name) == (f"limits.{kind}_scale", factor, "shoulder_pan_joint")
    assert error.advised == pytest.approx((low, high))
    advised = re.search(rf"use timing.limits.{kind}_scale in \[([^,]+), ([^\]]+)\]", detail(error))
    assert advised is not None and (float(advised[1]), float(advised[2])) == error.advised, detail(error)
    for advice in error.advised:
        timing = dict(method=METHODS[method], limits=LimitRequest(kinds=constraints, overrides=overrides, scales={kind: advice}))
        assert plan(build_problem(UR5, TWO, **timing, sampling=Sampling(dt=10.0))).duration > 0.0


def test_unlimited_joints_take_any_scale():
    """``inf`` (no limit) times a factor is still no limit: geering_2r has no velocity limits."""
    arm = robots.load("geering_2r")
    path = WaypointPath(np.array([[0.0, 0.0], [0.5, 0.3]]))
    result = plan(build_problem(arm, path, METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "torque"), scales={"velocity": 1e-3}), sampling=Sampling(dt=0.01)))
    assert result.duration > 0.0


def test_http_names_the_scale(client):
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": TWO.waypoints.tolist()},
        "timing": {"method": "jerk_limited", "constraints": list(JERK_KINDS), "limits": {"jerk": [1e-6] * 6, "jerk_scale": 1e-3}},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert "timing.limits.jerk_scale = 0.001" in response.json()["detail"]
