"""A value the schema refuses gets the fix: the nearest allowed choice (same but for case first,
then the closest spelling), tried here to work; a number sent as a string says so; a value that
fits no member of a union, or a flat list where rows are expected, is one sentence saying what
is accepted instead of one error per member or per item."""

from __future__ import annotations

import copy

import pytest

from tests.conftest import UR5_WAYPOINTS

BODY = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS[:2]}}


def _with(change: dict) -> dict:
    body = copy.deepcopy(BODY)
    for place, value in change.items():
        holder: dict = body
        *parents, last = place.split(".")
        for parent in parents:
            holder = holder.setdefault(parent, {})
        holder[last] = value
    return body


#: (field changed, wrong value, the suggestion).
NEAREST = [
    ("timing.method", "topra", "toppra"),
    ("timing.method", "TOPPRA", "toppra"),
    ("timing.method", "trapezoid", "trapezoidal"),
    ("path.kind", "waypoint", "waypoints"),
]


@pytest.mark.parametrize(("field", "wrong", "meant"), NEAREST, ids=[case[1] for case in NEAREST])
def test_a_wrong_choice_gets_the_nearest_allowed_one_and_that_one_works(client, field, wrong, meant):
    answer = client.post("/v1/trajectories", json=_with({field: wrong}))
    assert answer.status_code == 422, answer.text
    error = answer.json()["errors"][0]
    assert error["field"] == field
    assert error["message"].endswith(f"not {wrong!r}: did you mean {meant!r}?")
    fixed = client.post("/v1/trajectories", json=_with({field: meant, "timing.duration": 2.0} if meant == "trapezoidal" else {field: meant}))
    assert fixed.status_code == 200, fixed.text


def test_a_robot_name_in_the_wrong_case_gets_the_catalog_name(client):
    answer = client.post("/v1/trajectories", json=_with({"robot": "UR5"}))
    assert answer.status_code == 404
    assert answer.json()["detail"].startswith("no robot named 'UR5' (did you mean 'ur5'?); catalog robots:")


def test_an_upload_key_in_the_wrong_case_gets_the_right_one(client):
    errors = client.post("/v1/robots", json={"URDF": "<robot name='a'/>"}).json()["errors"]
    assert {"field": "URDF", "message": "Extra inputs are not permitted: did you mean 'urdf'?"} in errors


def test_a_number_sent_as_a_string_says_so(client):
    errors = client.post("/v1/trajectories", json=_with({"output.dt": "0.01"})).json()["errors"]
    assert errors == [
        {"field": "output.dt", "message": "Input should be a valid number; got the string '0.01'; write the number without quotes"}
    ]


@pytest.mark.parametrize("text", ["nan", "1e999", "-inf"])
def test_a_non_finite_number_as_a_string_is_not_told_to_drop_the_quotes(client, text):
    """NaN and infinity are refused without quotes too: the advice would not work."""
    errors = client.post("/v1/trajectories", json=_with({"output.dt": text})).json()["errors"]
    assert errors == [{"field": "output.dt", "message": f"Input should be a valid number; got the string {text!r}"}]


def test_the_path_kinds_suggested_are_the_schemas():
    from toptraj.service.value_hints import PATH_KINDS

    assert PATH_KINDS == ("waypoints", "cartesian", "free")


def test_a_value_fitting_no_member_of_a_union_is_one_sentence(client):
    errors = client.post("/v1/robots", json={"urdf": "<robot name='a'/>", "joint_limits": 5}).json()["errors"]
    assert errors == [{"field": "joint_limits", "message": "should be a string or an object; got a number"}]


@pytest.mark.parametrize("flat", [[0, 0, 0, 0, 0, 0], [0, -1.2, 1, 0, 0.5, 0], [0, -1.2]])  # ints and floats mixed too
def test_a_flat_list_where_rows_are_expected_is_one_sentence_with_the_shape(client, flat):
    errors = client.post("/v1/robots/ur5/skeleton", json={"q": flat}).json()["errors"]
    assert len(errors) == 1 and errors[0]["field"] == "q", errors
    assert errors[0]["message"].startswith("should be a list of lists (one list of values per item, e.g. [[0, 0], [1, 1]]); got a flat list")
