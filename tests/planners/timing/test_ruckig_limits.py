"""ruckig on an arm whose joints have no velocity, acceleration or jerk limit (the paper arms
limit torques only): nothing bounds the move, and a 200 was a jump of about 0.3 ms between two
samples at rest. It is refused, saying which limits to set, and setting one plans."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS, WaypointPath, build_problem, plan
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.problem.problem import LimitRequest, Sampling
from toptraj.service.problems import detail

MOVE = WaypointPath(np.array([[0.0, 0.0], [0.5, -0.4]]))
KINDS = ("velocity", "acceleration", "jerk")


def test_ruckig_without_any_finite_limit_is_refused_with_advice():
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(robots.load("yamamoto_2r"), MOVE, METHODS["ruckig"], limits=LimitRequest(kinds=KINDS)))
    assert (refused.value.field, refused.value.rule) == ("constraints", "no_limit_bounds_speed")
    assert "give the limits in timing.limits" in detail(refused.value)
    assert "add 'torque'" not in detail(refused.value)  # ruckig holds no torque limit


def test_the_advice_plans_a_motion_within_the_limit_set():
    jerk = 50.0
    result = plan(build_problem(
        robots.load("yamamoto_2r"), MOVE, METHODS["ruckig"], limits=LimitRequest(kinds=KINDS, overrides={"jerk": [jerk, jerk]}),
        sampling=Sampling(dt=1e-3),
    ))
    # rest to rest over 0.5 rad at one jerk: the duration of the three-phase jerk profile,
    # T = 4 (distance / (2 jerk))^(1/3) for the leading joint (4 phases of equal length).
    distance = 0.5
    assert result.duration == pytest.approx(4.0 * (distance / (2.0 * jerk)) ** (1.0 / 3.0), rel=1e-6)
    jerks = np.diff(result.samples.qdd, axis=0) / np.diff(result.samples.t)[:, None]
    assert np.max(np.abs(jerks)) <= 1.005 * jerk
