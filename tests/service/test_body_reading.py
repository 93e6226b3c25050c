"""A JSON body the service cannot read says why and how to fix it: a body sent without
``Content-Type: application/json`` (curl's default form encoding) is a 415 naming the header on
every route that takes JSON; a body that is no JSON a 422 with its line, column and the
parser's message (not a character offset that looks like an array index); an empty body a 422
that says so. The CLI's files and a batch's lines are read the same way."""

from __future__ import annotations

import json

import pytest

from tests.paths import ROOT
from toptraj.service.batches.lines import parse_line
from toptraj.service.cli import main

SPLINE = (ROOT / "examples" / "ur5_spline.json").read_bytes()
JSON = {"content-type": "application/json"}

#: Every route that takes a JSON body.
JSON_ROUTES = ["/v1/trajectories", "/v1/trajectories/compare", "/v1/cells", "/v1/jobs", "/v1/batches", "/v1/robots", "/v1/robots/ur5/skeleton"]


@pytest.mark.parametrize("route", JSON_ROUTES)
@pytest.mark.parametrize("content_type", [None, "application/x-www-form-urlencoded", "text/plain"])
def test_a_body_without_the_json_content_type_is_a_415_naming_the_header(client, route, content_type):
    headers = {} if content_type is None else {"content-type": content_type}
    answer = client.post(route, content=SPLINE, headers=headers)
    assert answer.status_code == 415, answer.text
    assert answer.headers["content-type"] == "application/problem+json"
    assert answer.json()["detail"] == "send the header Content-Type: application/json (curl: -H 'Content-Type: application/json')"


def test_json_with_a_charset_or_a_plus_json_type_is_read(client):
    for content_type in ("application/json; charset=utf-8", "application/vnd.toptraj+json"):
        answer = client.post("/v1/robots/ur5/skeleton", content=b'{"q": [[0, 0, 0, 0, 0, 0]]}', headers={"content-type": content_type})
        assert answer.status_code == 200, answer.text


#: (body, the detail's expected message after "body: ").
MALFORMED = [
    (b'{"robot": "ur5",\n "path": {"waypoints": [[0, 0, 0, 0, 0, 0]\n', "line 3, column 1: Expecting ',' delimiter (the text ends before the JSON does"),
    (b'{"robot": "ur5",\n  "path": {}\n    "timing": {}}', "line 3, column 5: Expecting ',' delimiter"),
    (b'{"robot": "ur5", "path": {},}', "line 1, column 29: Expecting property name enclosed in double quotes (a comma before '}': JSON allows no trailing comma"),
    (b"{'robot':'ur5'}", "line 1, column 2: Expecting property name enclosed in double quotes (JSON needs double quotes"),
]


@pytest.mark.parametrize(("body", "message"), MALFORMED)
def test_a_body_that_is_no_json_says_line_column_and_why(client, body, message):
    answer = client.post("/v1/trajectories", content=body, headers=JSON)
    assert answer.status_code == 422, answer.text
    problem = answer.json()
    assert problem["detail"].startswith(f"body: {message}"), problem
    assert problem["errors"][0]["field"] == "body"


@pytest.mark.parametrize("route", ["/v1/trajectories", "/v1/jobs", "/v1/robots"])
def test_an_empty_body_says_it_is_empty_and_what_to_send(client, route):
    answer = client.post(route, content=b"", headers=JSON)
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"] == 'body: the body is empty; send a JSON object (e.g. {"robot": "ur5", "path": ...})'


def test_the_cli_says_where_a_file_is_no_json(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text('{"robot": "ur5",\n  "path": {}\n    "timing": {}}')
    assert main(["plan", str(bad)]) == 2
    problem = json.loads(capsys.readouterr().err)
    assert problem["status"] == 400
    assert problem["detail"] == f"{bad}: line 3, column 5: Expecting ',' delimiter"


def test_the_cli_says_a_file_is_empty(tmp_path, capsys):
    empty = tmp_path / "empty.json"
    empty.write_text("\n")
    assert main(["plan", str(empty)]) == 2
    assert json.loads(capsys.readouterr().err)["detail"] == f"{empty}: the request is empty; send a JSON object (e.g. {{\"robot\": \"ur5\", \"path\": ...}})"


def test_a_batch_line_that_is_no_json_says_its_line_and_column():
    line = parse_line(7, b"{'robot': 'ur5'}")
    assert line.problem is not None
    status, problem = line.problem
    assert status == 422  # as POST /v1/trajectories answers a body that is no JSON
    assert json.loads(problem)["detail"].startswith("line 7: column 2: Expecting property name enclosed in double quotes (JSON needs double quotes")


def test_a_string_never_closed_is_read_in_linear_time():
    """The depth count skips strings with a pattern that cannot backtrack: a body of 40
    waypoints with a quote never closed (a typo) took seconds per added character before.
    Run in a child process, so that a relapse fails the test instead of hanging the suite."""
    import subprocess
    import sys

    script = (
        "from toptraj.service.strict_json import nesting_depth\n"
        "waypoints = ', '.join(['[0, 0, 0, 0, 0, 0]'] * 40)\n"
        "body = ('{\"robot\": \"ur5\", \"note\": \"abc, \"path\": {\"waypoints\": [' + waypoints + ']}}' + ' x' * 50_000).encode()\n"
        "print(nesting_depth(body))\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().isdigit()


def test_a_body_in_another_encoding_than_utf8_is_a_422_naming_utf8(client):
    """A UTF-16 body (where a quote byte can be half of another character, so that brackets
    hide from the depth count) is refused as JSON between systems must be UTF-8 (RFC 8259);
    a UTF-8 byte order mark is ignored."""
    body = json.loads(SPLINE)
    for encoding in ("utf-16", "utf-32"):
        answer = client.post("/v1/trajectories", content=json.dumps(body).encode(encoding), headers=JSON)
        assert answer.status_code == 422, answer.text
        assert answer.json()["detail"] == "body: the body is not UTF-8 text; send JSON encoded as UTF-8"
        line = parse_line(2, json.dumps(body).encode(encoding))
        assert line.problem is not None and line.problem[0] == 422
        assert json.loads(line.problem[1])["detail"].startswith("line 2: the line is not UTF-8 text (")
    answer = client.post("/v1/trajectories", content=b"\xef\xbb\xbf" + SPLINE, headers=JSON)
    assert answer.status_code == 200, answer.text
    assert parse_line(3, b"\xef\xbb\xbf" + SPLINE).problem is None


def test_the_cli_refuses_a_file_nested_too_deep_before_reading_it(tmp_path, capsys):
    from toptraj.service.strict_json import MAX_DEPTH

    deep = tmp_path / "deep.json"
    deep.write_text('{"robot": "ur5", "path": {"waypoints": ' + "[" * 5000 + "]" * 5000 + "}}")
    assert main(["plan", str(deep)]) == 2
    problem = json.loads(capsys.readouterr().err)
    assert problem["detail"] == f"{deep}: the request is nested too deeply: it nests arrays and objects 5002 deep; a request nests at most {MAX_DEPTH} levels"
