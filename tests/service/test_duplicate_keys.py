"""A key given twice in one object of a JSON body is refused with a 422 naming the key and its
place, wherever the service reads JSON (every HTTP body, the lines of a batch, the CLI's
files), instead of the last one silently winning; the size and nesting bounds hold as before."""

from __future__ import annotations

import json

import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj.service.batches.lines import parse_line
from toptraj.service.cli import main
from toptraj.service.strict_json import MAX_DEPTH, DuplicateKey, loads

PATH = json.dumps({"waypoints": UR5_WAYPOINTS[:2]})
URDF = '<robot name="r"><link name="a"/></robot>'

#: (route, body with a key given twice, the key's place).
CASES = [
    ("/v1/trajectories", '{"robot": "ur5", "robot": "panda", "path": PATH}'.replace("PATH", PATH), "robot"),
    (
        "/v1/trajectories",
        '{"robot": "ur5", "path": PATH, "timing": {"zones": [{"s_range": [0.1, 0.2], "tool_speed": 0.1, "tool_speed": 0.2}]}}'.replace("PATH", PATH),
        "timing.zones[0].tool_speed",
    ),
    ("/v1/trajectories/compare", '{"robot": "ur5", "path": PATH, "methods": ["toppra"], "methods": ["quintic"]}'.replace("PATH", PATH), "methods"),
    ("/v1/cells", '{"arms": [{"robot": "ur5", "waypoints": [[0,0,0,0,0,0]], "robot": "ur5"}]}', "arms[0].robot"),
    ("/v1/jobs", '{"trajectory": {"robot": "ur5", "path": PATH}, "budget_s": 5, "budget_s": 6}'.replace("PATH", PATH), "budget_s"),
    ("/v1/batches", '{"requests": [{"robot": "ur5", "path": PATH}, {"robot": "ur5", "robot": "ur5"}]}'.replace("PATH", PATH), "requests[1].robot"),
    ("/v1/robots", '{"urdf": URDF, "name": "a", "name": "b"}'.replace("URDF", json.dumps(URDF)), "name"),
    ("/v1/robots/ur5/skeleton", '{"q": [[0,0,0,0,0,0]], "q": [[1,0,0,0,0,0]]}', "q"),
]


@pytest.mark.parametrize(("route", "body", "place"), CASES, ids=[f"{route} {place}" for route, _, place in CASES])
def test_a_key_given_twice_in_a_body_is_refused_naming_it_and_its_place(client, route, body, place):
    answer = client.post(route, content=body.encode(), headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text
    assert answer.headers["content-type"] == "application/problem+json"
    problem = answer.json()
    key = place.rpartition(".")[2].partition("[")[0]
    assert problem["errors"] == [{"field": place, "message": problem["detail"].split(": ", 1)[1]}]
    assert problem["detail"].startswith(f"{place}: the key {key!r} is given 2 times in one object")


def test_the_same_keys_in_different_objects_are_no_duplicates(client):
    body = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS[:2]}, "timing": {"method": "toppra"}, "output": {"format": "samples"}}
    answer = client.post("/v1/trajectories", content=json.dumps(body).encode(), headers={"content-type": "application/json"})
    assert answer.status_code == 200, answer.text


def test_the_place_is_found_inside_lists_and_the_count_given():
    with pytest.raises(DuplicateKey) as refused:
        loads('[1, {"x": [{"k": 1}, {"k": 1, "k": 2, "k": 3}]}]')
    assert (refused.value.where, refused.value.key, refused.value.count) == ("[1].x[1].k", "k", 3)


def test_a_repeated_object_replaced_by_a_later_one_is_not_the_place_named():
    """The object holding ``method`` twice was replaced by the second ``timing``: the repeated
    ``timing`` is named, at the top, not a ``method`` the parsed body no longer holds."""
    with pytest.raises(DuplicateKey) as refused:
        loads('{"timing": {"method": 1, "method": 2}, "timing": {}}')
    assert (refused.value.where, refused.value.key, refused.value.count) == ("timing", "timing", 2)


def test_a_repeated_key_inside_a_kept_object_is_named_at_its_place():
    with pytest.raises(DuplicateKey) as refused:
        loads('{"a": {"b": {"c": 1, "c": 2}}, "a2": {"x": 1, "x": 2}}')
    assert (refused.value.where, refused.value.key) == ("a.b.c", "c")


def test_a_body_too_deep_is_still_refused_with_a_400(client):
    """A 400 saying how deep the body nests and how deep a request may, as a batch's line."""
    answer = client.post("/v1/trajectories", content=b"[" * 100_000, headers={"content-type": "application/json"})
    assert answer.status_code == 400
    assert answer.headers["content-type"] == "application/problem+json"
    problem = answer.json()
    assert problem["title"] == "Too deeply nested"
    assert problem["detail"] == f"the body is nested too deeply: it nests arrays and objects 100000 deep; a request nests at most {MAX_DEPTH} levels"
    line = json.loads(parse_line(1, b"[" * 100_000).problem[1])
    assert line["detail"].endswith(f"nested too deeply: it nests arrays and objects 100000 deep; a request nests at most {MAX_DEPTH} levels")


@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 1000])
def test_a_body_deeper_than_a_request_nests_is_refused_before_it_is_parsed(client, monkeypatch, depth):
    """Valid JSON nesting more than ``MAX_DEPTH`` levels, as a body or as a batch's line, is the
    same 400, before the parser builds anything from it; ``MAX_DEPTH`` levels are read (and
    then refused by the schema, with the place)."""
    from toptraj.service import strict_routes

    parsed = []
    monkeypatch.setattr(strict_routes, "loads", lambda data: parsed.append(data) or loads(data))
    waypoints = "[" * (depth - 2) + "0" + "]" * (depth - 2)
    body = f'{{"robot": "ur5", "path": {{"waypoints": {waypoints}}}}}'.encode()
    answer = client.post("/v1/trajectories", content=body, headers={"content-type": "application/json"})
    assert answer.status_code == 400, answer.text
    expected = f"nested too deeply: it nests arrays and objects {depth} deep; a request nests at most {MAX_DEPTH} levels"
    assert answer.json() == {"type": "about:blank", "title": "Too deeply nested", "status": 400, "detail": f"the body is {expected}"}
    assert parsed == []
    line = json.loads(parse_line(2, body).problem[1])
    assert line["title"] == "Too deeply nested" and line["detail"] == f"line 2: the line is {expected}"
    allowed = "[" * (MAX_DEPTH - 2) + "0" + "]" * (MAX_DEPTH - 2)
    read = client.post("/v1/trajectories", content=f'{{"robot": "ur5", "path": {{"waypoints": {allowed}}}}}', headers={"content-type": "application/json"})
    assert read.status_code == 422 and read.json()["detail"].startswith("path.waypoints[0][0]: ")
    assert len(parsed) == 1


def test_a_batch_line_giving_a_key_twice_is_its_own_422():
    line = parse_line(3, b'{"robot": "ur5", "path": {"waypoints": [[0,0,0,0,0,0]], "waypoints": []}}')
    status, body = line.problem
    assert status == 422
    assert json.loads(body)["detail"].startswith("line 3: path.waypoints: the key 'waypoints' is given 2 times")


def test_a_batch_line_with_nan_is_still_no_json():
    status, _ = parse_line(1, b'{"robot": "ur5", "path": {"waypoints": [[NaN]]}}').problem
    assert status == 422


def test_the_cli_refuses_a_key_given_twice(tmp_path, capsys):
    request = tmp_path / "request.json"
    request.write_text('{"robot": "ur5", "path": PATH, "timing": {"method": "toppra", "method": "quintic"}}'.replace("PATH", PATH))
    assert main(["plan", str(request)]) == 1
    problem = json.loads(capsys.readouterr().err)
    assert problem["status"] == 422 and problem["errors"][0]["field"] == "timing.method"
