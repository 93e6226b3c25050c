"""A recorded path whose waypoints nearly repeat (an arm standing still while its encoders
jitter) is timed along the path without the repeats, by every method alike, with a warning;
``path.min_spacing`` 0 keeps them."""

from __future__ import annotations

import numpy as np
import pytest

from tests.service.answer_limits import assert_limits_held

#: Geering's arm, each waypoint recorded twice 1e-7 to 2.5e-7 rad apart (1e-7 of the path's
#: length): toppra answered 422, "exceeds the torque limit of joint 'phi' by 45078 %", and
#: min_cost "stops the motion between s = 1.7e-09 and s = 3.3e-09"; phase_plane 1.647 s, which
#: the turns between the pairs slow by 77 %.
RECORDED = [
    [-2.5851639838868, 0.45957506280275984], [-2.585163861363286, 0.4595752802508681],
    [-2.515538118916415, 0.9592371448619603], [-2.515538028951253, 0.959237305647413],
    [-2.504562997130843, 1.3804592784804566], [-2.504563042555862, 1.3804591902902126],
    [-2.5765325518004953, 1.6907505731822627], [-2.5765327252897157, 1.6907504567977558],
    [-2.70715284965496, 1.9226019194433648], [-2.707152886317835, 1.9226019389125033],
]
DROPPED = [1, 3, 5, 7, 8]  # the second of each pair, and the first of the last (the goal is kept)
KEPT = [row for index, row in enumerate(RECORDED) if index not in DROPPED]


def _body(method: str, waypoints=RECORDED, **path) -> dict:
    return {
        "robot": "geering_2r", "path": {"waypoints": waypoints, **path},
        "timing": {"method": method, "constraints": ["velocity", "acceleration", "torque"]}, "output": {"dt": 0.0005},
    }


@pytest.mark.parametrize("method", ["toppra", "phase_plane", "min_cost"])
def test_nearly_repeated_waypoints_are_dropped_and_every_method_times_the_path_without_them(client, method):
    body = _body(method)
    answer = client.post("/v1/trajectories", json=body)
    assert answer.status_code == 200, answer.text[:300]
    answer = answer.json()
    assert_limits_held(body, answer)
    (warning,) = [w for w in answer["warnings"] if "were dropped" in w]
    assert warning.startswith("path.waypoints [1, 3, 5, 7, 8] (5 in all) were dropped as near repeats (the rule: a waypoint")
    assert "within 0.0001 of the path's joint-space length, 1.51, of the one kept before it, or of the last, goes)" in warning
    assert "none lies farther than 2.5e-07 rad or m from a waypoint kept" in warning
    assert warning.endswith("path.min_spacing = 0 keeps them")
    assert answer["samples"]["q"][0] == pytest.approx(RECORDED[0], abs=1e-12)  # both ends as given
    assert answer["samples"]["q"][-1] == pytest.approx(RECORDED[-1], abs=1e-12)
    kept = client.post("/v1/trajectories", json=_body(method, KEPT)).json()
    assert answer["duration"] == kept["duration"]  # the path of the waypoints kept, timed alike
    reference = client.post("/v1/trajectories", json=_body("phase_plane", KEPT)).json()
    assert answer["duration"] == pytest.approx(reference["duration"], rel=answer["accuracy"]["relative_gap"] + reference["accuracy"]["relative_gap"])


def test_min_spacing_zero_keeps_the_near_waypoints_and_phase_plane_times_their_turns(client):
    """With every waypoint kept the spline turns between each pair and the arm nearly stops
    there: phase_plane times it 77 % longer, and the dropped-waypoint warning is absent."""
    kept = client.post("/v1/trajectories", json=_body("phase_plane", min_spacing=0)).json()
    merged = client.post("/v1/trajectories", json=_body("phase_plane")).json()
    assert not [w for w in kept["warnings"] if "dropped" in w]
    assert kept["duration"] == pytest.approx(1.647, abs=1e-3) and merged["duration"] == pytest.approx(0.929, abs=1e-3)


def test_a_min_spacing_out_of_range_is_a_422_naming_the_field(client):
    refused = client.post("/v1/trajectories", json=_body("toppra", min_spacing=0.5))
    assert refused.status_code == 422
    problem = refused.json()
    assert "path.min_spacing" in problem["detail"] and "0.01" in problem["detail"]


def test_a_single_near_waypoint_says_it_and_its_distance(client):
    waypoints = [RECORDED[0], RECORDED[2], list(np.add(RECORDED[2], [3e-6, 0.0])), RECORDED[4]]
    (warning,) = client.post("/v1/trajectories", json=_body("toppra", waypoints)).json()["warnings"]
    assert warning.startswith("path.waypoints[2] was dropped as a near repeat (the rule: a waypoint within 0.0001 of")
    assert "it lies 3e-06 rad or m from a waypoint kept" in warning
    assert warning.endswith("path.min_spacing = 0 keeps it")


def test_a_waypoint_out_of_range_is_refused_by_its_index_as_given_even_beside_a_near_one(client):
    """Checked before any waypoint is dropped: the refusal names the waypoint as given, and a
    waypoint outside the joint range is refused, not dropped as a near repeat of one inside."""
    waypoints = [RECORDED[0], RECORDED[1], RECORDED[2], [9.0, 0.5]]
    refused = client.post("/v1/trajectories", json=_body("toppra", waypoints))
    assert refused.status_code == 422 and "path.waypoints[3][0]" in refused.json()["detail"], refused.text[:300]


def test_exact_and_near_repeats_are_told_apart(client):
    """An exact repeat is dropped whatever path.min_spacing says; the advice to keep near ones
    names only them."""
    waypoints = [RECORDED[0], RECORDED[2], RECORDED[2], RECORDED[3], RECORDED[4]]
    exact, near = client.post("/v1/trajectories", json=_body("toppra", waypoints)).json()["warnings"]
    assert exact == "path.waypoints[2] repeats the waypoint before it and was dropped"
    assert near.startswith("path.waypoints[3] was dropped as a near repeat") and "it lies 1.8e-07 rad or m" in near
    assert near.endswith("path.min_spacing = 0 keeps it")
    (kept,) = client.post("/v1/trajectories", json=_body("phase_plane", waypoints, min_spacing=0)).json()["warnings"]
    assert kept == exact


def test_a_sharp_turn_between_waypoints_just_beyond_the_spacing_is_told_with_a_spacing_that_drops_it(client):
    """Two z1 waypoints 6.1e-4 rad apart (2e-4 of the path's length, kept) between which the
    path turns by 152 degrees: the arm nearly stops there, which went unsaid. The warning names
    the pair and a path.min_spacing that drops one of them; followed, the motion is 14 % shorter
    and toppra, which refused the path, times it too."""
    from tests.service.test_other_method_advice import SHARP_PAIR

    body = {**SHARP_PAIR, "timing": {**SHARP_PAIR["timing"], "method": "phase_plane"}}
    answer = client.post("/v1/trajectories", json=body).json()
    (warning,) = [w for w in answer["warnings"] if "turns sharply" in w]
    assert "path.waypoints[2] and [3], 0.00061 rad or m apart" in warning and "turning by 152 degrees" in warning
    advised = float(warning.rsplit("path.min_spacing = ", 1)[1].split()[0])
    followed = {**body, "path": {**body["path"], "min_spacing": advised}}
    shorter = client.post("/v1/trajectories", json=followed).json()
    assert not [w for w in shorter["warnings"] if "turns sharply" in w]
    assert [w for w in shorter["warnings"] if w.startswith("path.waypoints[3] was dropped as a near repeat")]
    assert shorter["duration"] < 0.87 * answer["duration"]
    timed = client.post("/v1/trajectories", json={**followed, "timing": SHARP_PAIR["timing"]})
    assert timed.status_code == 200 and timed.json()["duration"] == pytest.approx(shorter["duration"], rel=1e-3)
