"""The console script: ``toptraj plan|compare FILE|-`` and ``toptraj plot``; answers on stdout,
errors as problem+json on stderr with a non-zero exit, quiet on a closed pipe."""

from __future__ import annotations

import io
import json
import shutil
import subprocess
import sys

import pytest

from tests.conftest import UR5_WAYPOINTS
from tests.paths import ROOT
from toptraj.service.cli import main


def test_plan_prints_the_response(tmp_path, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}}))
    assert main(["plan", str(request)]) == 0
    captured = capsys.readouterr()
    body = json.loads(captured.out)
    assert body["robot"] == "ur5" and body["method"] == "phase_plane" and body["duration"] > 0
    assert len(body["samples"]["q"][0]) == 6 and captured.err == ""


def test_plan_reports_bad_input_on_stderr(tmp_path, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "nope", "path": {"waypoints": UR5_WAYPOINTS}}))
    assert main(["plan", str(request)]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and json.loads(captured.err)["status"] == 404
    assert main(["plan", str(tmp_path / "missing.json")]) == 2
    assert "missing.json" in json.loads(capsys.readouterr().err)["detail"]
    request.write_text('{"robot": "ur5", "path": {"waypoints": [[0, 0]]}}')
    assert main(["plan", str(request)]) == 1
    assert json.loads(capsys.readouterr().err)["status"] == 422


def test_plan_reads_stdin(monkeypatch, capsys):
    monkeypatch.setattr("sys.stdin", io.StringIO(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}})))
    assert main(["plan", "-"]) == 0
    assert json.loads(capsys.readouterr().out)["robot"] == "ur5"


@pytest.mark.parametrize("command", ["plan", "compare"])
def test_the_compare_example_runs(command, capsys):
    assert main([command, str(ROOT / "examples" / "compare_methods.json")]) == 0
    results = json.loads(capsys.readouterr().out)["results"]
    expected = json.loads((ROOT / "examples" / "compare_methods.json").read_text())["methods"]
    assert [r["method"] for r in results] == expected and all(r["duration"] > 0 for r in results)


def test_csv_format_prints_csv(tmp_path, capsys):
    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "output": {"format": "csv"}}))
    assert main(["plan", str(request)]) == 0
    assert capsys.readouterr().out.startswith("t,q.shoulder_pan_joint,")


def test_a_closed_pipe_ends_quietly(tmp_path):
    request = tmp_path / "request.json"  # an answer of about 1 MB, far more than a pipe holds
    request.write_text(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "output": {"dt": 0.001}}))
    command = f"{sys.executable} -m toptraj.service.cli plan - < {request} | head -c 20"
    done = subprocess.run(["bash", "-c", command], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.stdout == '{"robot":"ur5","meth'
    assert done.stderr == ""


def test_a_reader_gone_is_no_error(tmp_path, monkeypatch, capsys):
    class ClosedPipe(io.BytesIO):
        def write(self, data):
            raise BrokenPipeError(32, "Broken pipe")

    from toptraj.service import commands

    request = tmp_path / "request.json"
    request.write_text(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}}))
    assert commands._run(str(request), commands._trajectory, out=ClosedPipe()) == 0
    assert capsys.readouterr().err == ""


def test_plot_writes_a_page_with_the_three_figures(tmp_path, capsys):
    out = tmp_path / "page.html"
    assert main(["plot", str(ROOT / "examples" / "ur5_spline.json"), "-o", str(out)]) == 0
    page = out.read_text()
    assert page.count("Plotly.newPlot") == 3 and "Phase plane" in page and "stroboscopically" in page
    assert "https://cdn" not in page.split("</script>")[0][:2000]  # the library is inlined, not fetched
    missing = tmp_path / "none.html"
    assert main(["plot", str(tmp_path / "nope.json"), "-o", str(missing)]) == 2 and not missing.exists()


@pytest.mark.skipif(shutil.which("make") is None or not (ROOT / "Makefile").exists(), reason="make (the README's set-up) is not installed here")
def test_make_serve_takes_host_and_port():
    """The README's serve command listens where HOST and PORT say, 127.0.0.1:8000 by default."""
    def serve_line(*assignments):
        printed = subprocess.run(["make", "-n", "-s", "serve", *assignments], cwd=ROOT, capture_output=True, text=True, check=True).stdout
        return next(line for line in printed.splitlines() if "toptraj serve" in line)

    assert serve_line().endswith("toptraj serve --host 127.0.0.1 --port 8000")
    assert serve_line("HOST=0.0.0.0", "PORT=8080").endswith("toptraj serve --host 0.0.0.0 --port 8080")


def test_serve_logs_each_request_only_when_asked(monkeypatch):
    """`toptraj serve` runs uvicorn without its access log (a line per request costs the
    event loop about 0.2 ms), and with it under `--access-log`."""
    import uvicorn

    calls = []
    monkeypatch.setattr(uvicorn, "run", lambda *args, **kwargs: calls.append(kwargs))
    monkeypatch.setenv("TOPTRAJ_PLAN_WORKERS", "1")
    assert main(["serve", "--workers", "1"]) == 0
    assert main(["serve", "--workers", "1", "--access-log"]) == 0
    assert [call["access_log"] for call in calls] == [False, True]
