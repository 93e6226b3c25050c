"""Waypoints that repeat a neighbour, or nearly (within ``min_spacing`` of the path's length),
are dropped before the path is built: the first and the last are kept."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj.planners.errors import InvalidRequest
from toptraj.planners.problem.requests import DEFAULT_MIN_SPACING, WaypointPath
from toptraj.planners.problem.waypoints import without_repeats

STRAIGHT = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1.0], [3.0, 1.0]])


def _length(waypoints: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())


def test_waypoints_farther_apart_than_the_spacing_are_kept_as_given():
    spec = WaypointPath(STRAIGHT)
    assert without_repeats(spec) == (spec, ())


def test_a_jittering_stand_still_is_one_waypoint_and_the_note_says_how_near_they_were():
    jitter = np.array([[1.0, 0.0], [1.0 + 3e-7, 1e-7], [1.0 - 2e-7, 0.0], [1.0, 4e-7]])
    waypoints = np.vstack([STRAIGHT[:1], jitter, STRAIGHT[2:]])
    spec, (note,) = without_repeats(WaypointPath(waypoints))
    assert np.array_equal(spec.waypoints, waypoints[[0, 1, 5, 6]])
    assert note.rule == "waypoints_dropped" and note.facts["indices"] == (2, 3, 4)
    assert note.facts["nearest"] == pytest.approx(np.linalg.norm(jitter[3] - jitter[0]))  # the largest distance merged
    assert note.facts["length"] == pytest.approx(_length(waypoints)) and not note.facts["coincident"]


def test_the_goal_is_kept_and_the_waypoint_nearly_on_it_is_dropped():
    waypoints = np.vstack([STRAIGHT, STRAIGHT[-1] + [4e-5, 0.0]])  # a settling after the goal, 1e-5 of the length
    spec, (note,) = without_repeats(WaypointPath(waypoints))
    assert np.array_equal(spec.waypoints, waypoints[[0, 1, 2, 4]])
    assert note.facts["indices"] == (3,)


def test_exact_repeats_say_so_and_min_spacing_zero_keeps_every_waypoint_that_differs():
    waypoints = np.vstack([STRAIGHT[:2], STRAIGHT[1:2], STRAIGHT[1:2] + 1e-9, STRAIGHT[2:]])
    spec, (note,) = without_repeats(WaypointPath(waypoints, min_spacing=0.0))
    assert note.facts["coincident"] and note.facts["indices"] == (2,)
    assert np.array_equal(spec.waypoints, np.delete(waypoints, 2, axis=0))
    spec, (note,) = without_repeats(WaypointPath(waypoints))
    assert note.facts["indices"] == (2, 3) and not note.facts["coincident"]


def test_the_spacing_is_a_share_of_the_path_length():
    """A waypoint just beyond the share stays, one just within it goes: the rule scales with the path."""
    for scale in (1e-3, 1.0, 1e3):
        path = STRAIGHT * scale
        spacing = DEFAULT_MIN_SPACING * _length(path)
        beyond = np.vstack([path[:2], path[1:2] + [0.0, 1.01 * spacing], path[2:]])
        assert len(without_repeats(WaypointPath(beyond))[0].waypoints) == 5
        within = np.vstack([path[:2], path[1:2] + [0.0, 0.99 * spacing], path[2:]])
        assert len(without_repeats(WaypointPath(within))[0].waypoints) == 4


def test_a_spacing_out_of_range_is_refused_and_a_path_that_stays_put_too():
    with pytest.raises(InvalidRequest) as refused:
        without_repeats(WaypointPath(STRAIGHT, min_spacing=0.5))
    assert refused.value.field == "min_spacing"
    with pytest.raises(InvalidRequest) as refused:
        without_repeats(WaypointPath(np.zeros((3, 2))))
    assert refused.value.rule == "all_waypoints_coincide"
