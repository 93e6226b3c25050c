"""The console script: ``toptraj plan request.json``."""

from __future__ import annotations

import json

from service.cli import main
from tests.conftest import UR5_WAYPOINTS


def test_plan_prints_the_response(tmp_path, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}}))
    assert main(["plan", str(request)]) == 0
    body = json.loads(capsys.readouterr().out)
    assert body["robot"] == "ur5" and body["method"] == "phase_plane" and body["duration"] > 0
    assert len(body["samples"]["q"][0]) == 6


def test_plan_reports_bad_input(tmp_path, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "nope", "path": {"waypoints": UR5_WAYPOINTS}}))
    assert main(["plan", str(request)]) == 1
    assert json.loads(capsys.readouterr().out)["status"] == 404
    assert main(["plan", str(tmp_path / "missing.json")]) == 2
