"""``toptraj plan`` and ``toptraj plot`` of a cell body (one with ``arms``, as the shipped
``examples/cell_two_ur5.json``): the same answer as ``POST /v1/cells``, CSV when the body asks
for it, a cell's own schema errors, and a page of the cell's plots."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.paths import ROOT
from toptraj import robots
from toptraj.service.cell_plots import arms_figure
from toptraj.service.cli import main

EXAMPLE = ROOT / "examples" / "cell_two_ur5.json"


def test_plan_answers_a_cell_as_the_cells_endpoint(patient_client, capsys):
    assert main(["plan", str(EXAMPLE)]) == 0
    printed = json.loads(capsys.readouterr().out)
    response = patient_client.post("/v1/cells", json=json.loads(EXAMPLE.read_text()))
    assert response.status_code == 200, response.text
    assert printed == response.json()
    assert printed["min_distance"]["guaranteed"] >= 0.02


def test_plan_of_a_cell_gives_csv_and_the_cells_schema_errors(tmp_path, capsys):
    body = json.loads(EXAMPLE.read_text())
    request = tmp_path / "cell.json"
    request.write_text(json.dumps(body | {"format": "csv"}))
    assert main(["plan", str(request)]) == 0
    assert capsys.readouterr().out.startswith("t,arms[0].q.shoulder_pan_joint,")
    del body["arms"][0]["robot"]
    request.write_text(json.dumps(body))
    assert main(["plan", str(request)]) == 1
    problem = json.loads(capsys.readouterr().err)
    assert problem["status"] == 422 and problem["detail"] == "arms[0].robot: Field required"


def test_plot_of_a_cell_writes_its_diagram_joints_and_arms(tmp_path, capsys):
    out = tmp_path / "cell.html"
    assert main(["plot", str(EXAMPLE), "-o", str(out)]) == 0
    page = out.read_text()
    assert page.count("Plotly.newPlot") == 3 and "Coordination diagram" in page and "stroboscopically" in page
    assert "https://cdn" not in page.split("</script>")[0][:2000]  # the library is inlined, not fetched


def test_each_arm_of_the_plot_stands_on_its_base():
    # arms[1] stands at (1.2, 0, 0) turned half a turn about z: its first joint is the ur5's
    # shoulder placement (from the model) turned and moved there
    ur5 = robots.load("ur5")
    q = np.array([[1.5, -0.5, 0.5, 0.0, 0.0, 0.0]])
    turned = np.diag([-1.0, -1.0, 1.0])
    answer = {
        "t": [0.0],
        "arms": [
            {"robot": "ur5", "samples": {"q": q}, "base": {"position": [0.0, 0.0, 0.0], "rotation": np.eye(3)}},
            {"robot": "ur5", "samples": {"q": q}, "base": {"position": [1.2, 0.0, 0.0], "rotation": turned}},
        ],
    }
    traces = arms_figure(answer).data
    shoulder = np.asarray(ur5.model.jointPlacements[1].translation)
    first = np.array([traces[1].x[0], traces[1].y[0], traces[1].z[0]])
    assert first == pytest.approx(turned @ shoulder + [1.2, 0.0, 0.0], abs=1e-12)
    assert [traces[0].x[0], traces[0].y[0], traces[0].z[0]] == pytest.approx(shoulder, abs=1e-12)


def test_compare_and_plot_methods_of_a_cell_say_which_command_takes_it(tmp_path, capsys):
    out = tmp_path / "cell.html"
    for argv in (["compare", str(EXAMPLE), "--json"], ["plot", str(EXAMPLE), "-o", str(out), "--methods", "toppra"]):
        assert main(argv) == 1
        problem = json.loads(capsys.readouterr().err)
        assert problem["status"] == 422 and "is planned by toptraj plan and drawn by toptraj plot (without --methods)" in problem["detail"]
        assert "belongs in" not in problem["detail"]
    assert not out.exists()
