"""POST /v1/cells: two arms timed together, their answer on one clock, and the 4xx of a bad
cell (issue 37)."""

from __future__ import annotations

import copy
import json
import re

import numpy as np
import pytest

from tests.paths import ROOT

EXAMPLE = json.loads((ROOT / "examples" / "cell_two_ur5.json").read_text())


@pytest.fixture(scope="module")
def answer(patient_client):
    response = patient_client.post("/v1/cells", json=EXAMPLE | {"format": "joint_trajectory"})
    assert response.status_code == 200, response.text
    return response.json()


def _points(arm: dict) -> tuple[np.ndarray, np.ndarray]:
    points = arm["joint_trajectory"]["points"]
    t = np.array([p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"] for p in points])
    return t, np.array([p["positions"] for p in points])


def test_both_arms_are_sampled_on_one_clock_from_start_to_end(answer):
    (t1, q1), (t2, q2) = (_points(arm) for arm in answer["arms"])
    assert np.array_equal(t1, t2) and t1[0] == 0.0 and t1[-1] == pytest.approx(answer["sampled_duration"], abs=1e-9)
    assert np.allclose(t1, answer["t"], atol=1e-9)
    for q, arm in ((q1, EXAMPLE["arms"][0]), (q2, EXAMPLE["arms"][1])):
        assert np.allclose(q[0], arm["waypoints"][0], atol=1e-9) and np.allclose(q[-1], arm["waypoints"][-1], atol=1e-9)
    assert answer["arms"][0]["joint_trajectory"]["joint_names"][0] == "shoulder_pan_joint"


def test_each_arm_echoes_its_payload_and_base_with_units(patient_client, answer):
    first, second = answer["arms"]
    assert first["payload"] is None and second["payload"] is None
    assert first["base"]["position"] == [0.0, 0.0, 0.0] and second["base"]["position"] == [1.2, 0.0, 0.0]
    np.testing.assert_allclose(second["base"]["rotation"], EXAMPLE["arms"][1]["base"]["rotation"], atol=1e-12)
    np.testing.assert_allclose(second["base"]["gravity"], [0.0, 0.0, -9.81], atol=1e-12)
    assert second["base"]["units"]["position"] == "m"
    body = _cell(a1={"payload": {"mass": 2.0, "center_of_mass": [0.0, 0.0, 0.05]}}) | {"gravity": [0.0, 0.0, -9.8]}
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 200, response.text
    arms = response.json()["arms"]
    assert arms[0]["payload"] is None and arms[0]["base"]["gravity"] == pytest.approx([0.0, 0.0, -9.8], abs=1e-12)
    payload = arms[1]["payload"]
    assert (payload["mass"], payload["center_of_mass"], payload["frame"]) == (2.0, [0.0, 0.0, 0.05], "tool0")
    assert payload["inertia"] == [[0.0] * 3] * 3 and payload["units"]["mass"] == "kg"


def test_the_answer_reports_the_time_lost_and_the_diagram(answer):
    assert answer["time_lost"] == pytest.approx(answer["duration"] - max(answer["solo_durations"]))
    assert max(answer["solo_durations"]) < answer["duration"] <= answer["sequential_duration"]
    diagram = answer["diagram"]
    blocked = np.array(diagram["blocked"])
    s = np.array(diagram["s"])
    assert blocked.shape == (len(s), len(s)) and blocked.any() and not blocked[0, 0]
    curve = np.array(diagram["curve"])
    assert curve[0] == pytest.approx([0.0, 0.0]) and curve[-1] == pytest.approx([1.0, 1.0])
    assert (np.diff(curve, axis=0) >= -1e-12).all()
    # the curve never enters a cell of the collision region
    i, j = (np.clip(np.floor(curve[:, k] * (len(s) - 1)).astype(int), 0, len(s) - 2) for k in (0, 1))
    assert not (blocked[i, j] | blocked[i + 1, j] | blocked[i, j + 1] | blocked[i + 1, j + 1]).any()
    assert answer["min_distance"]["guaranteed"] >= EXAMPLE["clearance"]


def _cell(**change) -> dict:
    body = copy.deepcopy(EXAMPLE)
    for index, fields in change.items():
        body["arms"][int(index[1:])].update(fields)
    return body


def test_an_unknown_robot_is_a_404_naming_it(patient_client):
    response = patient_client.post("/v1/cells", json=_cell(a1={"robot": "ur55"}))
    assert response.status_code == 404 and "ur55" in response.json()["detail"]
    assert response.json()["detail"].startswith("arms[1].robot: no robot named 'ur55'")


@pytest.mark.parametrize("other", [{"path": {"kind": "cartesian", "points": [[0.4, 0.0, 0.3]]}}, {"kind": "free"}])
def test_a_path_of_another_kind_is_a_422_saying_what_is_served(patient_client, other):
    response = patient_client.post("/v1/cells", json=_cell(a1=other))
    assert response.status_code == 422
    detail = response.json()["detail"]
    assert detail.startswith("arms[1]") and "joint waypoints only" in detail and "POST /v1/trajectories" in detail
    assert next(iter(other)) in detail


@pytest.mark.parametrize(
    ("waypoints", "words"),
    [
        (
            [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]],
            "arms[1].waypoints[0] has 3 values; ur5 has 6 joints (shoulder_pan_joint, shoulder_lift_joint, elbow_joint, "
            "wrist_1_joint, wrist_2_joint, wrist_3_joint)",
        ),
        (
            [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [1.5, -0.5, 0.5, 0.0, 0.0]],
            "arms[1].waypoints[1] has 5 values; ur5 has 6 joints (shoulder_pan_joint, shoulder_lift_joint, elbow_joint, "
            "wrist_1_joint, wrist_2_joint, wrist_3_joint)",
        ),
        (
            [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0]] * 2,
            "arms[1] does not move: its 2 waypoints coincide. A cell times arms that move and keeps them apart from each "
            "other, not from an arm standing still: leave arms[1] out, or give it a waypoint that differs from the first",
        ),
        (
            [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [99.0, -0.5, 0.5, 0.0, 0.0, 0.0]],
            "arms[1].waypoints[1][0] = 99 is outside the limits [-6.28319, 6.28319] of joint 'shoulder_pan_joint'; joint "
            "values are in rad: if it is in degrees, give 1.72788 rad",
        ),
    ],
)
def test_bad_waypoints_of_an_arm_are_a_422_in_the_request_words(patient_client, waypoints, words):
    response = patient_client.post("/v1/cells", json=_cell(a1={"waypoints": waypoints}))
    assert response.status_code == 422
    assert response.json()["detail"] == words


def test_a_base_that_is_not_a_rotation_is_a_422_saying_where(patient_client):
    mirrored = {"position": [1.2, 0.0, 0.0], "rotation": [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]}
    response = patient_client.post("/v1/cells", json=_cell(a1={"base": mirrored}))
    assert response.status_code == 422
    detail = response.json()["detail"]
    assert detail.startswith("arms[1].base.rotation: rotation is not a rotation matrix: its determinant is -1 (a reflection)")
    assert "[[-1,0,0],[0,-1,0],[0,0,1]] turns the base half a turn about z" in detail, detail
    assert response.headers["content-type"].startswith("application/problem+json")


def test_arms_that_collide_at_their_start_are_a_422_naming_the_links(patient_client):
    response = patient_client.post("/v1/cells", json=_cell(a1={"base": {"position": [0.1, 0.0, 0.0]}}))
    assert response.status_code == 422
    detail = response.json()["detail"]
    assert detail.startswith("the arms collide at their start") and "link '" in detail
    assert "_0' of arms" not in detail  # the URDF's link names, not the capsules' names
    # the advice names where to put the base (followed below) and what clearance would do
    match = re.search(r"is (-?[\d.e-]+) m from link .*the clearance is ([\d.e-]+) m\): set arms\[1\]\.base\.position to \[([^\]]+)\]", detail)
    assert match, detail
    distance = float(match.group(1))
    assert ("lower clearance to" in detail) == (distance > 0.0)


#: Two ur5s reaching along x, the second turned half a turn (facing the first) 0.6 m away.
FACING = [[0, -0.5, 0.5, 0, 0.3, 0], [1.5, -0.5, 0.5, 0, 0.3, 0]]


@pytest.mark.parametrize(
    "body",
    [
        _cell(a1={"base": {"position": [0.1, 0.0, 0.0]}}),
        _cell(a1={"base": {"position": [0.0, 0.0, 0.0]}}),
        _cell(a1={"base": {"position": [0.1234567, -0.0456789, 0.0001234]}}),  # advised to whole millimetres, as printed
        {"arms": [{"robot": "ur5", "waypoints": FACING},
                  {"robot": "ur5", "base": {"position": [0.6, 0, 0], "orientation": [0, 0, 1, 0]}, "waypoints": FACING}]},
    ],
    ids=["near", "same-point", "unround", "turned-towards"],
)
def test_the_base_position_advised_for_arms_that_collide_at_their_start_clears_them(patient_client, body):
    """The advice said how far to move the base, not where: moving it along the line between
    the bases made a turned arm's overlap worse, and two bases at one point had no direction."""
    detail = patient_client.post("/v1/cells", json=body).json()["detail"]
    match = re.search(r"set arms\[1\]\.base\.position to \[([^\]]+)\]", detail)
    assert match, detail
    followed = copy.deepcopy(body)
    followed["arms"][1]["base"]["position"] = [float(x) for x in match.group(1).split(",")]
    answered = patient_client.post("/v1/cells", json=followed)
    assert "collide at their start" not in answered.text, answered.text


def test_three_arms_are_answered_on_one_clock_with_every_pairs_diagram(patient_client):
    body = copy.deepcopy(EXAMPLE) | {"format": "joint_trajectory"}
    quarter = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    body["arms"].append(copy.deepcopy(body["arms"][0]) | {"base": {"position": [0.6, 1.1, 0.0], "rotation": quarter}})
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    times = [_points(arm)[0] for arm in answer["arms"]]
    assert len(times) == 3 and all(np.array_equal(t, times[0]) for t in times)
    assert [d["arms"] for d in answer["diagrams"]] == [[0, 1], [0, 2], [1, 2]]
    assert max(answer["solo_durations"]) <= answer["duration"] <= answer["sequential_duration"]
    assert answer["min_distance"]["guaranteed"] >= body["clearance"] and answer["schedule"].startswith("prioritized")


def test_three_arms_that_can_take_turns_in_no_order_are_a_422_naming_the_pairs_and_links(patient_client):
    """A third arm resting at its start and end where the facing pair passes: the 422 names both
    pairs, the links and where, in the request's words (``arms[i]``); its base moved back as
    advised, the cell is answered."""
    body = copy.deepcopy(EXAMPLE)
    quarter = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    reaching = [[0.0, -0.6, 0.6, 0.0, 0.3, 0.0], [0.0, -0.6, 0.6, 0.0, 1.0, 0.0], [0.0, -0.6, 0.6, 0.0, 1.7, 0.0]]
    body["arms"].append(copy.deepcopy(body["arms"][0]) | {"waypoints": reaching, "base": {"position": [0.6, 1.1, 0.0], "rotation": quarter}})
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 422, response.text[:300]
    detail = response.json()["detail"]
    assert "arms[0] and arms[2], and arms[1] and arms[2], can each take turns in neither order" in detail
    assert re.search(
        r"with arms\[0\] first, arms\[0\]'s link 'forearm_link' at s = [\d.]+ overlaps link 'forearm_link' of arms\[2\] "
        r"resting at its start by [\d.]+ m", detail,
    )
    assert "with arms[2] first, arms[1]'s link 'forearm_link'" in detail and "resting at its end by" in detail
    assert "move the bases of each such pair apart" in detail and "lower clearance" not in detail
    body["arms"][2]["base"]["position"] = [0.6, 1.8, 0.0]
    assert patient_client.post("/v1/cells", json=body).status_code == 200


def test_five_arms_are_a_422_naming_the_bound(patient_client):
    body = copy.deepcopy(EXAMPLE)
    body["arms"] += [copy.deepcopy(body["arms"][0]) | {"base": {"position": [0.0, 3.0 * k, 0.0]}} for k in range(1, 4)]
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 422 and "a cell has 5 arms; from 2 to 4 are served" in response.json()["detail"]
    nine = copy.deepcopy(EXAMPLE)
    nine["arms"] = (nine["arms"] * 5)[:9]  # past the schema's bound of 8
    assert patient_client.post("/v1/cells", json=nine).status_code == 422


def test_a_waypoint_of_the_wrong_length_is_a_422_naming_the_arm(patient_client):
    response = patient_client.post("/v1/cells", json=_cell(a0={"waypoints": [[0.0] * 5, [0.1] * 5]}))
    assert response.status_code == 422 and "arms[0]" in response.json()["detail"]


def test_the_example_at_a_clearance_its_timings_keep_is_a_200(patient_client):
    # at clearance 0.028 the example is answered with the arms 0.111 m apart or more
    response = patient_client.post("/v1/cells", json=EXAMPLE | {"clearance": 0.1})
    assert response.status_code == 200, response.text
    assert response.json()["min_distance"]["guaranteed"] >= 0.1


def test_one_arm_or_one_value_is_counted_in_the_singular(patient_client):
    one = copy.deepcopy(EXAMPLE)
    one["arms"] = one["arms"][:1]
    response = patient_client.post("/v1/cells", json=one)
    assert response.status_code == 422 and "a cell has 1 arm; from 2 to 4 are served" in response.json()["detail"]
    response = patient_client.post("/v1/cells", json=_cell(a1={"waypoints": [[0.0], [0.1]]}))
    assert response.status_code == 422 and "arms[1].waypoints[0] has 1 value; ur5 has 6 joints" in response.json()["detail"]


def test_a_cell_warns_of_limits_it_was_not_asked_to_hold_and_of_its_sampling(patient_client):
    """As a trajectory's answer: with velocity limits only, the arms' accelerations and torques
    run far past their limits (66 and 17 times), each named with how to hold it; samples a second
    apart on whole periods are too few to follow the 1.88 s motion and slow it to 2 s (6.3 %),
    both of which are said; the example as it is warns of nothing."""
    velocity_only = patient_client.post("/v1/cells", json=EXAMPLE | {"constraints": ["velocity"]}).json()
    found = {re.match(r"arms\[(\d)\]: the (\w+) of", text).groups() for text in velocity_only["warnings"]}
    assert found == {("0", "acceleration"), ("0", "torque"), ("1", "acceleration"), ("1", "torque")}, velocity_only["warnings"]
    arm0 = velocity_only["arms"][0]["samples"]
    tau = np.abs(np.asarray(arm0["tau"])).max()  # the answer's own samples exceed the torque limit (150 N m)
    assert tau > 150.0 and all(text.endswith("to constraints to hold it") for text in velocity_only["warnings"])
    coarse = patient_client.post("/v1/cells", json=EXAMPLE | {"dt": 1.0, "format": "joint_trajectory"}).json()
    few, slowed = coarse["warnings"]  # three samples of a 1.88 s motion, and the slowing
    scale = coarse["sampled_duration"] / coarse["duration"]
    assert few.startswith("dt = 1 s is more than a tenth of the motion") and "its 3 samples do not follow" in few
    assert coarse["sampled_duration"] == 2.0 and slowed.startswith(f"exact_period slows the motion by {100 * (scale - 1):.3g} %")
    assert patient_client.post("/v1/cells", json=EXAMPLE).json()["warnings"] == []


def test_an_arm_repeating_a_waypoint_drops_it_and_an_arm_standing_still_is_told_what_a_cell_does(patient_client):
    arms = copy.deepcopy(EXAMPLE["arms"])
    arms[1]["waypoints"] = [arms[1]["waypoints"][0], *arms[1]["waypoints"]]  # a recorded path that waits at its start
    repeated = patient_client.post("/v1/cells", json=EXAMPLE | {"arms": arms})
    assert repeated.status_code == 200, repeated.text[:300]
    assert repeated.json()["warnings"] == ["arms[1].waypoints[1] repeats the waypoint before it and was dropped"]
    assert repeated.json()["duration"] == pytest.approx(patient_client.post("/v1/cells", json=EXAMPLE).json()["duration"], rel=1e-9)
    arms[1]["waypoints"] = [arms[1]["waypoints"][0]] * 2
    still = patient_client.post("/v1/cells", json=EXAMPLE | {"arms": arms})
    assert still.status_code == 422 and still.json()["detail"].startswith(
        "arms[1] does not move: its 2 waypoints coincide. A cell times arms that move"
    ), still.text[:300]
    assert "remove" not in still.json()["detail"]


def test_a_base_turned_by_a_quaternion_or_by_a_four_digit_matrix_is_the_same_base(patient_client):
    """The second arm of the example stands turned half a turn about z: as the matrix
    [[-1,0,0],[0,-1,0],[0,0,1]], as the quaternion [0, 0, 1, 0] (a trajectory's mounting takes both)
    give the same cell; turned by 135 degrees, the matrix written with four digits (0.7071,
    orthonormal within 1e-3 only, refused before within 1e-6) gives the cell of the exact quaternion
    to the digits the matrix was given with."""
    planned = patient_client.post("/v1/cells", json=EXAMPLE).json()
    turned = copy.deepcopy(EXAMPLE)
    assert turned["arms"][1]["base"]["rotation"] == [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]
    del turned["arms"][1]["base"]["rotation"]
    turned["arms"][1]["base"]["orientation"] = [0.0, 0.0, 1.0, 0.0]
    quaternion = patient_client.post("/v1/cells", json=turned).json()
    assert quaternion["duration"] == pytest.approx(planned["duration"], rel=1e-9)
    np.testing.assert_allclose(quaternion["arms"][1]["base"]["rotation"], planned["arms"][1]["base"]["rotation"], atol=1e-12)
    turned["arms"][1]["base"]["orientation"] = [0.0, 0.0, float(np.sin(np.radians(67.5))), float(np.cos(np.radians(67.5)))]
    exact = patient_client.post("/v1/cells", json=turned)
    assert exact.status_code == 200, exact.text[:300]
    del turned["arms"][1]["base"]["orientation"]
    turned["arms"][1]["base"]["rotation"] = [[-0.7071, -0.7071, 0.0], [0.7071, -0.7071, 0.0], [0.0, 0.0, 1.0]]
    rounded = patient_client.post("/v1/cells", json=turned)
    assert rounded.status_code == 200, rounded.text[:300]
    assert rounded.json()["duration"] == pytest.approx(exact.json()["duration"], rel=1e-3)
    np.testing.assert_allclose(rounded.json()["arms"][1]["base"]["rotation"], exact.json()["arms"][1]["base"]["rotation"], atol=1e-4)
    turned["arms"][1]["base"]["orientation"] = [0.0, 0.0, 1.0, 0.0]
    both = patient_client.post("/v1/cells", json=turned)
    assert both.status_code == 422 and "give base.orientation or base.rotation, not both" in both.text


def test_a_trajectorys_mounting_on_a_cell_arm_says_where_the_pose_goes(patient_client):
    arms = copy.deepcopy(EXAMPLE["arms"])
    arms[1]["mounting"] = {"position": [1.2, 0.0, 0.0], "orientation": [0.0, 0.0, 1.0, 0.0]}
    refused = patient_client.post("/v1/cells", json=EXAMPLE | {"arms": arms}).json()
    assert refused["detail"].startswith("arms[1].mounting: Extra inputs are not permitted: a cell arm's pose in the world is its `base`")
    arms[1]["orientation"] = arms[1].pop("mounting")["orientation"]
    refused = patient_client.post("/v1/cells", json=EXAMPLE | {"arms": arms}).json()
    assert refused["detail"].endswith("'orientation' belongs in arms[i].base.orientation"), refused["detail"]


def test_arms_that_never_come_near_run_at_their_own_optimum_together(patient_client):
    """A 40-waypoint ur5 path and an arm 10 m away: each arm's own motion was timed on a grid of
    400 intervals without the single arm's limit gate, a limit exceeded between its points
    slowed the whole cell's clock by 3 %, and that loss was reported as coordination's
    (``time_lost`` 0.081 s). Timed as a single arm's path is, the arms run at once, the cell
    within the gate's tolerance (0.3 %) of the trajectory endpoint's own answer for that path."""
    i = np.arange(40)
    waypoints = np.round(np.column_stack([
        1.4 * np.cos(2 * np.pi * i / 40 + 3.9), -0.8 - 0.3 * np.sin(3 * i / 40 + 3.9), 1 + 0.4 * np.sin(4 * i / 40),
        0.3 * np.sin(i / 3), 0.5 + 0.2 * np.cos(i / 4), 0.1 * i / 40,
    ]), 3).tolist()
    cell = {"arms": [
        {"robot": "ur5", "waypoints": waypoints},
        {"robot": "ur5", "base": {"position": [10.0, 0.0, 0.0]}, "waypoints": [[0, -1, 1, 0, 0.5, 0], [0.1, -1, 1, 0, 0.5, 0]]},
    ]}
    answered = patient_client.post("/v1/cells", json=cell)
    assert answered.status_code == 200, answered.text
    body = answered.json()
    alone = patient_client.post("/v1/trajectories", json={
        "robot": "ur5", "path": {"kind": "waypoints", "waypoints": waypoints},
        "timing": {"method": "toppra", "constraints": ["velocity", "acceleration", "torque"]},
    }).json()
    assert body["schedule"] == "simultaneous"
    assert body["solo_durations"][0] == pytest.approx(alone["duration"], rel=2e-3)
    assert body["duration"] <= 1.003 * body["solo_durations"][0] and body["time_lost"] <= 0.003 * body["duration"]


@pytest.mark.parametrize(
    "base, detail",
    [
        ({"position": [1200, 0, 0]}, "arms[1].base.position[0]: 1200 is not within the accepted range [-1000, 1000] m"),
        (
            {"orientation": [0, 0, 180, 0]},
            "arms[1].base.orientation: orientation has norm above 2: not a rotation; give a unit quaternion [qx, qy, qz, qw] "
            "(norm 1 within 0.001)",
        ),
    ],
)
def test_a_base_out_of_range_is_worded_as_a_trajectory_s_mounting_is(patient_client, base, detail):
    """A cell arm's base took numpy's repr (``np.float64(1200.0)``) and pydantic's bare bound
    (``Input should be less than or equal to 2``) where a mounting says what it accepts."""
    response = patient_client.post("/v1/cells", json=_cell(a1={"base": base}))
    assert response.status_code == 422 and response.json()["detail"] == detail, response.text


def test_a_cell_of_one_arm_is_pointed_to_the_trajectory_endpoint(patient_client):
    body = copy.deepcopy(EXAMPLE)
    body["arms"] = body["arms"][:1]
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 422 and "plan a single arm with POST /v1/trajectories" in response.json()["detail"]
    assert "split the cell" not in response.json()["detail"]


@pytest.mark.parametrize(
    "where, field, words",
    [
        ("top", "zones", "timing.zones) are served for one arm by POST /v1/trajectories"),
        ("top", "obstacles", "obstacles are served for one arm by POST /v1/trajectories"),
        ("arm", "self_collision", "a cell always checks each arm's links against each other; leave it out"),
        ("arm", "timing", "give velocity_scale, acceleration_scale or torque_scale on the arm itself"),
    ],
)
def test_a_trajectory_field_in_a_cell_says_what_the_cell_does_instead(patient_client, where, field, words):
    """A bare "Extra inputs are not permitted" for a field a trajectory request takes."""
    body = copy.deepcopy(EXAMPLE)
    (body if where == "top" else body["arms"][0])[field] = {"method": "toppra"} if field == "timing" else [] if field != "self_collision" else True
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 422 and words in response.json()["detail"], response.text


def test_a_cell_gravity_pointing_up_is_warned_of_as_a_mounting_s_is(patient_client):
    body = copy.deepcopy(EXAMPLE)
    body["gravity"] = [0.0, 0.0, 9.81]
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 200, response.text
    (warning,) = [text for text in response.json()["warnings"] if "points up" in text]
    assert warning.startswith("gravity [0, 0, 9.81] points up (+z in the world)") and "an arm's base.orientation" in warning
    assert not [text for text in patient_client.post("/v1/cells", json=EXAMPLE).json()["warnings"] if "points up" in text]


def test_the_sampling_advice_for_a_short_cell_motion_is_a_period_a_cell_takes(patient_client):
    """A motion of 0.06 s at the default dt (0.01 s) has 7 samples: the advice was dt <= 0.0006 s,
    below the 1 ms a cell takes; it is 1 ms and the samples that gives (followed here)."""
    body = {"arms": [
        {"robot": "ur5", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [0.01, -1.2, 1, 0, 0.5, 0]]},
        {"robot": "ur5", "base": {"position": [3.0, 0.0, 0.0]}, "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [0.01, -1.2, 1, 0, 0.5, 0]]},
    ]}
    answer = patient_client.post("/v1/cells", json=body).json()
    (few,) = [text for text in answer["warnings"] if "samples do not follow" in text]
    match = re.search(r"dt <= ([\d.e-]+) s gives (\d+) samples", few)
    assert match and float(match.group(1)) == 0.001, few
    followed = patient_client.post("/v1/cells", json=body | {"dt": 0.001}).json()
    assert len(followed["t"]) >= int(match.group(2)) and not [t for t in followed["warnings"] if "samples do not follow" in t]


def test_arms_with_coulomb_friction_under_torque_limits_alone_are_timed_as_one_arm_is(patient_client):
    """Two z1s (joint friction) 3 m apart, torque limits alone: a coordinated curve the pair could
    not be timed along refused the whole cell ("no motion can follow the path"), though both arms
    can run at once; and the cell took the torque at rest without the friction the planning
    holds. The arms now run at once as the trajectory endpoint times one, their torques at rest
    with the friction opposing the path's tangent, every one within the limits."""
    path = [[0, 1.0, -1.0, 0, 0, 0], [0.5, 1.2, -1.2, 0.2, 0.2, 0.2]]
    cell = {"arms": [{"robot": "z1", "waypoints": path}, {"robot": "z1", "base": {"position": [3, 0, 0]}, "waypoints": path}],
            "constraints": ["torque"]}
    answered = patient_client.post("/v1/cells", json=cell)
    assert answered.status_code == 200, answered.text
    body = answered.json()
    alone = patient_client.post("/v1/trajectories", json={
        "robot": "z1", "path": {"waypoints": path}, "timing": {"method": "toppra", "constraints": ["torque"]}, "output": {"dt": 0.01},
    }).json()
    assert body["schedule"] == "simultaneous" and body["duration"] == pytest.approx(alone["duration"], rel=2e-3)
    torque_limit = np.array([30.0, 60.0, 30.0, 30.0, 30.0, 30.0])
    for arm in body["arms"]:
        tau = np.asarray(arm["samples"]["tau"])
        assert np.abs(tau / torque_limit).max() <= 1.003
        np.testing.assert_allclose(tau[-1], np.asarray(alone["samples"]["tau"])[-1], rtol=2e-2)  # at rest, with its friction
