"""The CSV answer read each way docs/http-api.md documents: its header is the first line, the
answer's metadata follow as ``#`` lines, then a row per sample; every reader that skips comment
lines reads the same numbers as the JSON answer."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS

BODY = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": "spline"},
    "timing": {"method": "phase_plane"},
    "output": {"dt": 0.01, "exact_period": True},
}


@pytest.fixture(scope="module")
def answers(client):
    json_answer = client.post("/v1/trajectories", json=BODY)
    csv_answer = client.post("/v1/trajectories", json=BODY | {"output": {**BODY["output"], "format": "csv"}})
    assert json_answer.status_code == 200 and csv_answer.status_code == 200, csv_answer.text
    return json_answer.json(), csv_answer.text


def _table(answer: dict) -> np.ndarray:
    samples = answer["samples"]
    return np.column_stack([np.array(samples["t"])[:, None]] + [np.array(samples[key]) for key in ("q", "qd", "qdd", "tau")])


def test_the_header_comes_first_then_the_metadata_then_the_rows(answers):
    answer, text = answers
    lines = text.splitlines()
    comments = [k for k, line in enumerate(lines) if line.startswith("#")]
    assert not lines[0].startswith("#") and comments == list(range(1, 1 + len(comments)))
    metadata = dict(line[2:].split(": ", 1) for line in lines if line.startswith("# ") and ": " in line)
    assert float(metadata["duration"].removesuffix(" s")) == answer["duration"]
    assert len(lines) == 1 + len(comments) + len(answer["samples"]["t"])


def test_csv_dictreader_over_the_lines_not_starting_with_hash(answers):
    answer, text = answers
    rows = list(csv.DictReader(line for line in io.StringIO(text) if not line.startswith("#")))
    assert [float(row["t"]) for row in rows] == answer["samples"]["t"]
    joint = answer["joint_names"][2]
    assert [float(row[f"tau.{joint}"]) for row in rows] == [tau[2] for tau in answer["samples"]["tau"]]


def test_numpy_loadtxt_and_genfromtxt(answers):
    answer, text = answers
    np.testing.assert_array_equal(np.loadtxt(io.StringIO(text), delimiter=",", comments="#", skiprows=1), _table(answer))
    named = np.genfromtxt(io.StringIO(text), delimiter=",", names=True, comments="#", deletechars="")
    assert named.dtype.names[:2] == ("t", f"q.{answer['joint_names'][0]}")
    np.testing.assert_array_equal(named["t"], answer["samples"]["t"])


def test_pandas_read_csv_with_comment(answers):
    pandas = pytest.importorskip("pandas")
    answer, text = answers
    frame = pandas.read_csv(io.StringIO(text), comment="#")
    assert list(frame.columns)[0] == "t" and all(dtype.kind == "f" for dtype in frame.dtypes)
    np.testing.assert_array_equal(frame.to_numpy(), _table(answer))


def test_the_documented_metadata_reader_keeps_every_warning(client):
    """docs/http-api.md's reader of the ``#`` lines: one value per key, and every
    ``# warning:`` line, in order (a dict of all the lines kept only the last warning)."""
    waypoints = [[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]]  # the wrist at its singularity first
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": waypoints}, "output": {"dt": 5.0, "exact_period": True}}
    answer = client.post("/v1/trajectories", json=body).json()
    text = client.post("/v1/trajectories", json=body | {"output": {"dt": 5.0, "exact_period": True, "format": "csv"}}).text
    assert len(answer["warnings"]) >= 2, answer["warnings"]
    pairs = [line[2:].rstrip("\n").split(": ", 1) for line in io.StringIO(text) if line.startswith("# ")]
    metadata = {key: value for key, value in pairs if key != "warning"}
    warnings = [value for key, value in pairs if key == "warning"]
    assert warnings == answer["warnings"]
    assert metadata["warnings"] == str(len(answer["warnings"])) and metadata["robot"] == "ur5"
