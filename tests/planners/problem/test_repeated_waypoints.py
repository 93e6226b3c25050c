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


def test_exact_repeats_and_near_ones_are_told_apart_and_min_spacing_zero_keeps_the_near_ones():
    waypoints = np.vstack([STRAIGHT[:2], STRAIGHT[1:2], STRAIGHT[1:2] + 1e-9, STRAIGHT[2:]])
    spec, (exact,) = without_repeats(WaypointPath(waypoints, min_spacing=0.0))
    assert exact.facts["coincident"] and exact.facts["indices"] == (2,)
    assert np.array_equal(spec.waypoints, np.delete(waypoints, 2, axis=0)) and spec.origin == (0, 1, 3, 4, 5)
    spec, (exact, near) = without_repeats(WaypointPath(waypoints))
    assert exact.facts["indices"] == (2,) and near.facts["indices"] == (3,) and not near.facts["coincident"]
    assert spec.origin == (0, 1, 4, 5)


def test_a_repeated_goal_drops_the_later_one():
    spec, (note,) = without_repeats(WaypointPath(np.vstack([STRAIGHT, STRAIGHT[-1:]])))
    assert note.facts["indices"] == (4,) and note.facts["coincident"] and len(spec.waypoints) == 4


def test_stop_and_go_and_via_points_keep_near_waypoints_unless_asked():
    """A ``linear`` path stops at each waypoint and via points pass each in its own segment: the
    spline's sharp turn does not arise, so only exact repeats go by default."""
    waypoints = np.vstack([STRAIGHT[:2], STRAIGHT[1:2] + [1e-6, 0.0], STRAIGHT[2:]])
    for interpolation in ("linear", "via"):
        assert without_repeats(WaypointPath(waypoints, interpolation)) == (WaypointPath(waypoints, interpolation), ())
        spec, (note,) = without_repeats(WaypointPath(waypoints, interpolation, min_spacing=1e-4))
        assert note.facts["indices"] == (2,) and len(spec.waypoints) == 4
    assert len(without_repeats(WaypointPath(waypoints, "blend"))[0].waypoints) == 4


def test_the_distance_told_is_from_the_nearest_waypoint_kept():
    """Waypoint 3 is dropped for waypoint 2, which is then dropped for the goal: 3 lies twice its
    step from the nearest waypoint kept, and the note says so (not the step)."""
    step = 1.8e-4
    waypoints = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0 - step, 0.0], [2.0 + step, 0.0]])
    spec, (note,) = without_repeats(WaypointPath(waypoints, min_spacing=2e-4 / _length(waypoints)))
    assert note.facts["indices"] == (2, 3) and spec.origin == (0, 1, 4)
    assert note.facts["nearest"] == pytest.approx(2 * step)


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


def test_sharp_turns_between_near_waypoints_are_told_and_smooth_dense_paths_are_not():
    from toptraj.planners.problem.waypoints import NEAR_PAIR

    t = np.linspace(0.0, 1.0, 1000)
    dense = np.column_stack([np.cos(3 * t), np.sin(2 * t)])  # near waypoints, gentle turns
    assert without_repeats(WaypointPath(dense)) == (WaypointPath(dense), ())
    step = 0.5 * NEAR_PAIR * _length(STRAIGHT)
    hook = np.vstack([STRAIGHT[:2], STRAIGHT[1:2] + [0.0, step], STRAIGHT[2:]])  # a right angle and back
    spec, (note,) = without_repeats(WaypointPath(hook))
    assert note.rule == "sharp_near_pairs" and [pair[:2] for pair in note.facts["pairs"]] == [(1, 2)]
    assert note.facts["pairs"][0][3] == pytest.approx(90.0)
    assert without_repeats(WaypointPath(hook, "linear")) == (WaypointPath(hook, "linear"), ())  # it stops there anyway
    followed, (dropped,) = without_repeats(WaypointPath(hook, min_spacing=note.facts["spacing"]))
    assert dropped.facts["indices"] == (2,) and len(followed.waypoints) == 4
