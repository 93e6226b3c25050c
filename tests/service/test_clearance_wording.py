"""The words of a path too close to an obstacle: a distance printed below the clearance it
breaks, and, where the path touches an obstacle, where, since no lower clearance helps."""

from __future__ import annotations

from toptraj.service.wordings import WORDING

FACTS = {"obstacle": 0, "link": "wrist_2_link", "s": 0.715, "clearance": 0.03, "closest": None, "fixed": False}


def test_a_distance_just_below_the_clearance_is_told_apart_from_it():
    detail = WORDING["path_in_collision"]({**FACTS, "distance": 0.0299996, "least": 0.0299})
    assert "comes within 0.0299996 m of path.obstacles[0]" in detail and "(the clearance is 0.03 m)" in detail
    assert detail.endswith("or lower path.clearance to 0.0299 m")


def test_a_path_that_touches_an_obstacle_says_where():
    detail = WORDING["path_in_collision"]({**FACTS, "distance": 0.02, "least": -0.001, "least_s": 0.8312})
    assert "comes within 0.02 m" in detail
    assert detail.endswith("(near s = 0.8312 the path touches an obstacle, or comes within about half a millimetre of one)")


def test_a_path_that_stays_clear_by_less_than_the_rounding_is_advised_a_clearance_of_zero():
    detail = WORDING["path_in_collision"]({**FACTS, "distance": 0.02, "least": 5e-5, "least_s": 0.8312})
    assert detail.endswith("or lower path.clearance to 0 m")
