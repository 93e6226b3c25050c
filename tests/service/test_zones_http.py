"""``timing.zones`` over HTTP: the answer lists where each zone lies and whether it bound the
timing; a bad zone is a 422 naming it (its index in the field), a method that does not hold
zones a 422 saying which do."""

from __future__ import annotations

import re

import pytest

from tests.conftest import UR5_WAYPOINTS

WELD_LINE = {"kind": "cartesian", "start": [0.3, -1.6, 1.7, -1.6, -1.57, 0.2], "positions": [[0.413, 0.542, 0.286]]}
MIDDLE = {"s_range": [1 / 3, 2 / 3], "tool_speed": 0.02}


def _body(zones, method="phase_plane", path=WELD_LINE) -> dict:
    return {
        "robot": "ur5",
        "path": path,
        "timing": {"method": method, "limits": {"tool_speed": 0.05}, "zones": zones},
        "output": {"dt": 0.05},
    }


def test_the_answer_lists_where_each_zone_lies_and_whether_it_bound(client):
    zones = [MIDDLE, {"box": {"center": [5.0, 5.0, 5.0], "size": [0.1, 0.1, 0.1]}, "velocity_scale": 0.5}]
    response = client.post("/v1/trajectories", json=_body(zones))
    assert response.status_code == 200, response.text
    middle, away = response.json()["zones"]
    assert middle["index"] == 0 and middle["ranges"] == [[1 / 3, 2 / 3]] and middle["binding"] is True
    assert abs(middle["peak"] - 1.0) <= 0.005
    assert away == {"index": 1, "ranges": [], "peak": 0.0, "binding": False}  # never entered
    (missed,) = [note for note in response.json()["warnings"] if note.startswith("timing.zones[1]")]
    assert missed.startswith("timing.zones[1] limits nothing: the tool point (origin of frame 'tool0') never enters its box")
    assert "grow each edge of timing.zones[1].box.size by more than" in missed
    assert "or move timing.zones[1].box.center towards the path" in missed
    assert not [note for note in response.json()["warnings"] if note.startswith("timing.zones[0]")]
    plain = client.post("/v1/trajectories", json=_body([])).json()
    assert plain["zones"] is None and plain["duration"] < response.json()["duration"]


@pytest.mark.parametrize(
    ("zones", "field", "words"),
    [
        ([MIDDLE, {"s_range": [0.6, 0.4], "tool_speed": 0.1}], "timing.zones[1]", "s_range [0.6, 0.4] runs backwards"),
        ([MIDDLE, {"s_range": [0.4, 0.4], "tool_speed": 0.1}], "timing.zones[1]", "s_range [0.4, 0.4] has zero length"),
        ([{"s_range": [1, 1], "velocity_scale": 0.5}], "timing.zones[0]", "give [s0, s1] with s1 > s0"),
        ([{"s_range": [0.2, 1.5], "tool_speed": 0.1}], "timing.zones[0].s_range[1]", "less than or equal to 1"),
        ([{"s_range": [-0.1, 0.5], "tool_speed": 0.1}], "timing.zones[0].s_range[0]", "greater than or equal to 0"),
        ([MIDDLE, MIDDLE, {"s_range": [0.2, 0.3], "tool_speed": -1.0}], "timing.zones[2].tool_speed", "not within"),
        ([{"s_range": [0.2, 0.3], "torque_scale": -0.5}], "timing.zones[0].torque_scale", "greater than 0"),
        ([{"s_range": [0.2, 0.3]}], "timing.zones[0]", "sets no limit"),
        ([{"s_range": [0.2, 0.3], "sphere": {"center": [0, 0, 0], "radius": 1}, "tool_speed": 1}], "timing.zones[0]", "exactly one"),
        ([MIDDLE] * 33, "timing.zones", "at most 32"),
    ],
)
def test_bad_zones_are_422_naming_the_zone(client, zones, field, words):
    response = client.post("/v1/trajectories", json=_body(zones))
    assert response.status_code == 422, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    errors = response.json()["errors"]
    assert errors[0]["field"] == field and words in errors[0]["message"], errors


def test_a_method_that_does_not_hold_zones_is_422(client):
    path = {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}
    response = client.post("/v1/trajectories", json=_body([MIDDLE], method="quintic", path=path))
    assert response.status_code == 422, response.text
    assert response.json()["detail"] == (
        "timing.zones are held by timing.method phase_plane or toppra along a given path (path.kind 'waypoints' with "
        "interpolation 'spline', 'linear' or 'blend', or 'cartesian'), not by 'quintic' here: choose one of those "
        "methods, or leave timing.zones out"
    )


def test_a_box_turned_by_no_unit_quaternion_is_422_naming_its_orientation(client):
    box = {"center": [0.4, 0.5, 0.3], "size": [0.1, 0.1, 0.1], "orientation": [0.0, 0.0, 0.0, 0.5]}
    response = client.post("/v1/trajectories", json=_body([MIDDLE, {"box": box, "velocity_scale": 0.5}]))
    assert response.status_code == 422, response.text
    assert response.json()["detail"] == (
        "timing.zones[1].box.orientation has norm 0.5: it is no rotation; give a unit quaternion [qx, qy, qz, qw] "
        "(norm 1 within 0.001), e.g. [0, 0, 0, 1] for a box along the world's axes"
    )


README_PATH = {"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [0.8, -1, 1.4, -0.5, 0.9, 0.3], [2, -1.3, 1.2, 0.2, 0.6, 1.2]]}


@pytest.mark.parametrize("scale", [0.01, 0.2])
def test_a_zone_too_weak_to_hold_the_arm_still_is_told_its_own_torque_scale(client, scale):
    """Holding the ur5 still inside a zone of a hundredth (or a fifth) of its torque needs 37.96 N m on
    shoulder_lift_joint, 25.3 % of its 150 N m: the advice is the zone's torque_scale 0.254 (the
    share, with room, rounded up), which plans the path, not the whole path's torque_scale, which
    would raise the limits outside the zone as well."""
    zone = {"s_range": [0.2, 0.5], "torque_scale": scale}
    body = {"robot": "ur5", "path": README_PATH, "timing": {"zones": [zone]}}
    refused = client.post("/v1/trajectories", json=body)
    assert refused.status_code == 422, refused.text[:300]
    detail = refused.json()["detail"]
    assert "holding still needs 37.96 N m on joint 'shoulder_lift_joint'" in detail
    assert f"against its limit of {150 * scale:g} N m; with timing.zones[0].torque_scale 0.254 (or more) every joint" in detail, detail
    assert "timing.limits.torque" not in detail
    followed = client.post("/v1/trajectories", json={**body, "timing": {"zones": [{**zone, "torque_scale": 0.254}]}})
    assert followed.status_code == 200, followed.text[:300]
    assert max(followed.json()["peak_utilization"]["torque"]) <= 1.005


def test_the_zone_remedy_holds_the_whole_path_or_is_not_given(client):
    """ur5 lifting its upper arm to the horizontal: holding it there needs 59.17 N m on
    shoulder_lift_joint (39 % of 150). Two overlapping zones at the end, of 5 % and 10 %: both
    are raised, together, and following the advice plans the path. With a torque scale of 0.3 the
    path's end, outside any zone, cannot hold it either: no zone is advised, only limits of the
    whole path."""
    lift = {"kind": "waypoints", "waypoints": [[0.0, -1.57, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]]}
    zones = [{"s_range": [0.9, 1.0], "torque_scale": 0.05}, {"s_range": [0.85, 1.0], "torque_scale": 0.1}]
    detail = client.post("/v1/trajectories", json={"robot": "ur5", "path": lift, "timing": {"zones": zones}}).json()["detail"]
    advised = re.findall(r"timing\.zones\[(\d)\]\.torque_scale ([\d.]+)", detail)
    assert [index for index, _ in advised] == ["0", "1"] and "timing.zones[0].torque_scale 0.395 and timing.zones[1]" in detail
    followed = [{**zone, "torque_scale": float(value)} for zone, (_, value) in zip(zones, advised, strict=True)]
    assert client.post("/v1/trajectories", json={"robot": "ur5", "path": lift, "timing": {"zones": followed}}).status_code == 200
    narrow = [{"s_range": [0.9051, 0.9079], "torque_scale": 0.05}, zones[1]]  # narrower than a grid interval
    detail = client.post("/v1/trajectories", json={"robot": "ur5", "path": lift, "timing": {"zones": narrow}}).json()["detail"]
    advised = re.findall(r"timing\.zones\[(\d)\]\.torque_scale ([\d.]+)", detail)
    assert [index for index, _ in advised] == ["0", "1"], detail
    followed = [{**zone, "torque_scale": float(value)} for zone, (_, value) in zip(narrow, advised, strict=True)]
    assert client.post("/v1/trajectories", json={"robot": "ur5", "path": lift, "timing": {"zones": followed}}).status_code == 200
    scaled = {"limits": {"torque_scale": 0.3}, "zones": [{"s_range": [0.0, 0.3], "torque_scale": 0.05}]}
    detail = client.post("/v1/trajectories", json={"robot": "ur5", "path": lift, "timing": scaled}).json()["detail"]
    assert "timing.zones" not in detail and "timing.limits.torque_scale 3.61" in detail, detail


def test_a_zone_scaling_a_limit_that_is_not_held_is_refused_and_the_advice_works(client):
    """torque_scale in a zone with torque left out of the constraints was answered without
    holding it (at 0.1, the zone's peak 3 times its limit, reported ``binding: true``). Refused
    naming the zone; adding torque to the constraints holds it."""
    body = {
        "robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
        "timing": {"constraints": ["velocity", "acceleration"], "zones": [{"s_range": [0.4, 0.6], "torque_scale": 0.5}]},
    }
    refused = client.post("/v1/trajectories", json=body)
    assert refused.status_code == 422, refused.text
    assert refused.json()["detail"] == (
        "timing.zones[0].torque_scale scales the torque limit, which is not among the limits held (velocity, acceleration): "
        'give timing.constraints with \'torque\' among them (["velocity", "acceleration", "torque"]), or leave '
        "timing.zones[0].torque_scale out"
    )
    # a method that holds no zones is told so first (its own advice; torque would not help ruckig)
    ruckig = client.post("/v1/trajectories", json={**body, "timing": {**body["timing"], "method": "ruckig", "constraints": None}})
    assert ruckig.status_code == 422 and "not by 'ruckig'" in ruckig.json()["detail"], ruckig.text
    followed = client.post("/v1/trajectories", json={**body, "timing": {**body["timing"], "constraints": ["velocity", "acceleration", "torque"]}})
    assert followed.status_code == 200, followed.text
    assert followed.json()["zones"][0]["peak"] <= 1.003


@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
def test_a_tool_speed_zone_on_the_first_stretch_of_a_linear_path_is_reported(client, method):
    """A linear path stops at its waypoints, each segment timed alone: a zone reaching the first
    segment only limits the tool speed there, and the answer's peaks take it from the segments
    that hold it (the others' lacking it was a 500)."""
    path = {"kind": "waypoints", "interpolation": "linear", "waypoints": UR5_WAYPOINTS[:3]}
    answer = client.post("/v1/trajectories", json={
        "robot": "ur5", "path": path, "timing": {"method": method, "zones": [{"s_range": [0.0, 0.2], "tool_speed": 0.1}]},
        "output": {"dt": 0.01},
    })
    assert answer.status_code == 200, answer.text
    assert 0.99 <= answer.json()["peak_utilization"]["tool_speed"] <= 1.005
