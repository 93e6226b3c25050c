"""Inputs that contradict each other are refused naming both and the fix, instead of one being
dropped without a word: a compare's ``timing.method`` outside its ``methods``, a method listed
twice, a job with both kinds, the client's ``method`` against ``timing``'s. A field of another
route says where it belongs."""

from __future__ import annotations

import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj.client.bodies import compare_request, trajectory_request
from toptraj.service.commands import compare_body

PATH = {"waypoints": UR5_WAYPOINTS[:2]}


def _refusal(client, route: str, body: dict) -> dict:
    answer = client.post(route, json=body)
    assert answer.status_code == 422, answer.text
    assert answer.headers["content-type"] == "application/problem+json"
    return answer.json()


def test_a_compare_whose_timing_method_is_not_among_its_methods_is_refused(client):
    body = {"robot": "ur5", "path": PATH, "methods": ["phase_plane"], "timing": {"method": "toppra"}}
    detail = _refusal(client, "/v1/trajectories/compare", body)["detail"]
    assert "timing.method 'toppra' conflicts with methods ['phase_plane']" in detail
    assert "add 'toppra' to methods, or leave timing.method out" in detail


def test_a_method_listed_twice_is_refused(client):
    body = {"robot": "ur5", "path": PATH, "methods": ["phase_plane", "quintic", "phase_plane"]}
    problem = _refusal(client, "/v1/trajectories/compare", body)
    assert problem["errors"] == [
        {"field": "methods", "message": "'phase_plane' is listed twice; list each method once: ['phase_plane', 'quintic']"}
    ]


def test_a_job_with_both_kinds_says_exactly_one(client):
    body = {"trajectory": {"robot": "ur5", "path": PATH}, "compare": {"robot": "ur5", "path": PATH}}
    problem = _refusal(client, "/v1/jobs", body)
    assert [error["field"] for error in problem["errors"]] == ["body"]
    assert "give exactly one of `trajectory`" in problem["detail"] and "not both" in problem["detail"]


#: (route, body, field, what its message must say).
ELSEWHERE = [
    ("/v1/jobs", {"request": {"robot": "ur5", "path": PATH}}, "request", "put the request under `trajectory`"),
    ("/v1/trajectories", {"robot": "ur5", "path": PATH, "methods": ["toppra"]}, "methods", "POST /v1/trajectories/compare"),
    ("/v1/trajectories/compare", {"robot": "ur5", "path": PATH, "methods": ["toppra"], "output": {}}, "output", "takes no `output`"),
]


@pytest.mark.parametrize(("route", "body", "field", "words"), ELSEWHERE, ids=[case[2] for case in ELSEWHERE])
def test_a_field_of_another_route_says_where_it_belongs(client, route, body, field, words):
    errors = _refusal(client, route, body)["errors"]
    assert any(error["field"] == field and words in error["message"] for error in errors), errors


def test_the_client_refuses_a_method_given_twice_with_two_values():
    with pytest.raises(ValueError, match=r"method='toppra' conflicts with timing=\{'method': 'quintic'\}"):
        trajectory_request("ur5", UR5_WAYPOINTS[:2], method="toppra", timing={"method": "quintic"})
    body = trajectory_request("ur5", UR5_WAYPOINTS[:2], method="toppra", timing={"method": "toppra", "grid_points": 50})
    assert body["timing"] == {"method": "toppra", "grid_points": 50}
    with pytest.raises(ValueError, match="conflicts with methods"):
        compare_request("ur5", UR5_WAYPOINTS[:2], methods=["phase_plane"], timing={"method": "toppra"})


def test_the_cli_compares_a_trajectory_body_under_other_methods_without_a_conflict(client):
    text = compare_body('{"robot": "ur5", "path": {"waypoints": [[0,0,0,0,0,0],[0.1,0,0,0,0,0]]}, "timing": {"method": "toppra"}}', ["quintic"])
    answer = client.post("/v1/trajectories/compare", content=text, headers={"content-type": "application/json"})
    assert answer.status_code == 200, answer.text
