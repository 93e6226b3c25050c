"""The library takes its own option objects, not the request's: a method object holding its
options, the limits asked for, the boundary states. The rules among one object's fields are
checked when it is made and raise errors that carry their facts; the rules between it and the
rest of the problem are ``build_problem``'s; each rule is raised in one place."""

from __future__ import annotations

import re

import numpy as np
import pytest

import toptraj.planners
import toptraj.planners.problem.requests
from tests.paths import ROOT
from toptraj import robots
from toptraj.planners import METHODS, BoundaryStates, LimitRequest, TimeLaw, WaypointPath, build_problem
from toptraj.planners.errors import Conflicting, InvalidRequest, NotServed, OutOfRange
from toptraj.planners.generators.joint_moves import Unsynchronized, ViaPoints
from toptraj.planners.problem.ranges import TRAPEZOID_FRACTION
from toptraj.planners.timing.laws.splines import MAX_SUPPORTING_POINTS, MIN_SUPPORTING_POINTS
from toptraj.planners.timing.min_cost import MinCostMethod

ARM = robots.load("geering_2r")
TWO = WaypointPath(np.array([[0.2, 0.3], [0.6, 1.0]]))


def test_the_request_mirror_has_left_the_library():
    assert not hasattr(toptraj.planners.problem.requests, "Timing")
    assert not hasattr(toptraj.planners, "Timing")
    assert "Timing" not in toptraj.planners.__all__


@pytest.mark.parametrize(
    "options, error_type, facts",
    [
        ({"name": "cubic", "blend": "cycloidal"}, NotServed,
         {"field": "law.blend", "value": "cycloidal", "method": "cubic", "rule": "blend_needs_trapezoidal", "alternatives": ("trapezoidal",)}),
        ({"name": "phase_plane", "supporting_points": 8}, NotServed,
         {"field": "law.supporting_points", "value": 8, "method": "phase_plane", "rule": "needs_time_law"}),
        ({"name": "trapezoidal", "fractions": (0.6, 0.4)}, InvalidRequest,
         {"field": "law.trapezoid", "value": (0.6, 0.4), "rule": "trapezoid_order"}),
        ({"name": "trapezoidal", "fractions": (0.0005, 0.5)}, OutOfRange,
         {"field": "law.trapezoid.tau1", "value": 0.0005, "low": TRAPEZOID_FRACTION.low, "high": TRAPEZOID_FRACTION.high}),
        ({"name": "quintic", "supporting_points": MAX_SUPPORTING_POINTS + 1}, OutOfRange,
         {"field": "law.supporting_points", "value": MAX_SUPPORTING_POINTS + 1, "low": MIN_SUPPORTING_POINTS,
          "high": MAX_SUPPORTING_POINTS, "rule": "count_out_of_range"}),
    ],
)
def test_a_time_law_refuses_options_that_do_not_go_together_when_made(options, error_type, facts):
    with pytest.raises(error_type) as refused:
        TimeLaw(**options)
    assert {name: getattr(refused.value, name) for name in facts} == facts


def test_a_time_law_builds_its_method_with_its_options():
    law = TimeLaw("trapezoidal", fractions=(0.2, 0.9), supporting_points=8).method()
    assert (law.name, law.supporting_points) == ("trapezoidal", 8)
    assert (law.profile.law.tau1, law.profile.law.tau2) == (0.2, 0.9)
    assert TimeLaw("quintic").method() is METHODS["quintic"]


def test_min_cost_refuses_a_negative_weight_when_made():
    with pytest.raises(OutOfRange) as refused:
        MinCostMethod(-1e-3)
    facts = refused.value
    assert (facts.field, facts.value, facts.low, facts.rule) == ("method.torque_weight", -1e-3, 0.0, "negative_weight")


def test_joints_on_their_own_need_a_time_law_when_made():
    with pytest.raises(NotServed) as refused:
        Unsynchronized(METHODS["phase_plane"])
    facts = refused.value
    assert (facts.field, facts.value, facts.method, facts.rule) == ("law.synchronization", "none", "phase_plane", "unsynchronized_needs_law")


def test_the_problem_refuses_a_spline_law_with_a_moving_boundary():
    law = TimeLaw("quintic", supporting_points=8).method()
    with pytest.raises(Conflicting) as refused:
        build_problem(ARM, TWO, law, boundary=BoundaryStates(start_velocity=np.array([0.1, 0.175])))
    facts = refused.value
    assert (facts.field, facts.value, facts.fields, facts.rule) == ("law.supporting_points", 8, ("boundary",), "law_from_rest")
    assert build_problem(ARM, TWO, law, boundary=BoundaryStates(start_velocity=np.zeros(2))).method is law


def test_via_points_take_their_generator():
    via = WaypointPath(np.array([[0.2, 0.3], [0.4, 0.5], [0.6, 1.0]]), "via")
    with pytest.raises(NotServed) as refused:
        build_problem(ARM, via, METHODS["cubic"])
    assert (refused.value.field, refused.value.rule) == ("interpolation", "via_points_need_their_generator")
    asked = LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [1.0, 1.0], "acceleration": [2.0, 2.0]})
    problem = build_problem(ARM, via, ViaPoints(METHODS["cubic"]), limits=asked)
    assert problem.method.family == "generator"


def test_the_problem_keeps_what_was_asked():
    asked = LimitRequest(kinds=("velocity",), overrides={"velocity": [1.0, 2.0]}, margin=0.1)
    problem = build_problem(ARM, TWO, METHODS["cubic"], limits=asked, duration=3.0, grid=50)
    assert (problem.requested, problem.duration, problem.grid, problem.boundary) == (asked, 3.0, 50, BoundaryStates())
    assert problem.limits.velocity == pytest.approx([0.9, 1.8])


#: The rules of the option objects and of the request's shape: each raised in one place.
MOVED_RULES = (
    "blend_needs_trapezoidal", "needs_time_law", "trapezoid_order", "count_out_of_range", "law_spline_failed", "law_from_rest",
    "negative_weight", "unsynchronized_needs_law", "weight_needs_min_cost", "options_need_search",
)


def test_each_rule_is_raised_in_one_place():
    sources = [path.read_text() for folder in ("planners", "robots", "service") for path in (ROOT / folder).rglob("*.py")]
    for rule in MOVED_RULES:
        count = sum(len(re.findall(rf'rule="{rule}"', text)) for text in sources)
        assert count == 1, rule
