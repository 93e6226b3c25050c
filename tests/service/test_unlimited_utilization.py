"""A joint without a finite limit of a kind has no utilization of it: the answer says null
(the JSON, its schema, the CSV's metadata, the client's typed results, the compare table),
never 0.0, which reads as a limit far from reached."""

from __future__ import annotations

import math

import numpy as np

from toptraj.client.results import Utilization
from toptraj.service.compare_table import compare_table
from toptraj.service.schemas.answers import UtilizationPublic

#: geering_2r has torque limits only (velocity and acceleration limits null in its catalog).
BODY = {
    "robot": "geering_2r",
    "path": {"kind": "waypoints", "waypoints": [[0.3, 0.2], [1.0, -1.0]]},
    "timing": {"method": "phase_plane", "constraints": ["torque"]},
    "output": {"dt": 0.01},
}


def test_a_kind_without_limits_reads_null_not_zero(client):
    response = client.post("/v1/trajectories", json=BODY)
    assert response.status_code == 200, response.text
    answer = response.json()
    peaks = answer["peak_utilization"]
    assert peaks["velocity"] == [None, None] and peaks["acceleration"] == [None, None]
    assert max(abs(v) for row in answer["samples"]["qd"] for v in row) > 0.1  # the joints do move
    assert math.isclose(max(peaks["torque"]), 1.0, abs_tol=3e-3)  # the torque limit binds
    UtilizationPublic.model_validate(peaks)
    typed = Utilization.from_body(peaks)
    assert np.isnan(typed.velocity).all() and np.isfinite(typed.torque).all()
    table = compare_table({"results": [{"method": "phase_plane", **{k: answer[k] for k in ("duration", "peak_utilization", "warnings", "solve_ms")}}]})
    assert "torque" in table.splitlines()[1]  # the highest peak is a real one


def test_the_csv_metadata_writes_null(client):
    response = client.post("/v1/trajectories", json=BODY | {"output": {"dt": 0.01, "format": "csv"}})
    assert response.status_code == 200, response.text
    lines = {line.split(":")[0]: line for line in response.text.splitlines() if line.startswith("# peak_utilization.")}
    assert lines["# peak_utilization.velocity"] == "# peak_utilization.velocity: null,null"
    assert lines["# peak_utilization.acceleration"] == "# peak_utilization.acceleration: null,null"
    assert "null" not in lines["# peak_utilization.torque"]


def test_a_cell_arms_unlimited_joint_reads_null():
    from types import SimpleNamespace

    from toptraj.service.cell_answers import reported_utilization

    limits = SimpleNamespace(velocity=np.array([np.inf, 2.0]), torque=np.array([5.0, 5.0]))
    reported = reported_utilization({"velocity": np.array([0.0, 0.75]), "torque": np.array([1.0, 0.5])}, limits)
    assert reported == {"velocity": [None, 0.75], "torque": [1.0, 0.5]}
