"""``toptraj batch`` resumes an output file by cutting it back to its whole result lines. Given
a file that is no output of a batch (the request file itself as ``-o``, or any other file), it
cut that file to nothing: the requests were lost. Only a last line without its newline (an
interrupted write) is cut; a whole line that is no result line leaves the file untouched and
the command answers a 400 that says so."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.paths import ROOT
from toptraj.service.batches.lines import ForeignOutput, resume_output

REQUEST = json.dumps({"robot": "geering_2r", "path": {"kind": "waypoints", "waypoints": [[0.0, 0.0], [0.5, 0.3]]}})
RESULT = json.dumps({"line": 1, "key": "ab" * 32, "status": 200, "body": {"duration": 1.0}})


@pytest.mark.parametrize(
    "text",
    [REQUEST + "\n", RESULT + "\n" + REQUEST + "\n", "notes of a week\n", RESULT + "\n\n", RESULT + "\n" + '{"line": 2}\n'],
    ids=["requests", "results then a request", "text", "results then a blank line", "a line without status"],
)
def test_a_file_that_is_no_output_is_left_as_it_is(tmp_path, text):
    path = tmp_path / "out.jsonl"
    path.write_text(text)
    with pytest.raises(ForeignOutput, match="no result line"):
        resume_output(path)
    assert path.read_text() == text


def test_an_interrupted_last_line_is_still_cut(tmp_path):
    path = tmp_path / "out.jsonl"
    path.write_text(RESULT + "\n" + RESULT[:30])
    assert resume_output(path) == {1: 200}
    assert path.read_text() == RESULT + "\n"


def test_the_request_file_as_output_is_refused_and_kept(tmp_path):
    requests = tmp_path / "requests.jsonl"
    requests.write_text(REQUEST + "\n")
    done = subprocess.run(
        [sys.executable, "-m", "toptraj.service.cli", "batch", str(requests), "-o", str(requests)],
        capture_output=True, text=True, timeout=60, cwd=ROOT,
    )
    assert done.returncode == 2, done.stderr
    problem = json.loads(done.stderr.strip().splitlines()[-1])
    assert problem["status"] == 400 and "request file" in problem["detail"]
    assert requests.read_text() == REQUEST + "\n"
