"""The console script: ``toptraj plan|compare FILE|-`` and ``toptraj plot``; answers on stdout,
errors as problem+json on stderr with a non-zero exit, quiet on a closed pipe."""

from __future__ import annotations

import io
import json
import os
import re
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
    request.write_text('{"robot": "ur5", "grid_points": ' + "9" * 5000 + "}")  # JSON, but no number Python reads
    assert main(["plan", str(request)]) == 2
    assert json.loads(capsys.readouterr().err)["detail"].endswith("a number has more than 4300 digits; a request's numbers (joint values, limits, settings) need a few")


def test_plan_reports_where_and_which_limit_as_the_http_problem_does(tmp_path, capsys, client):
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]]},
            "timing": {"limits": {"torque_scale": 0.2}}}
    request = tmp_path / "request.json"
    request.write_text(json.dumps(body))
    assert main(["plan", str(request)]) == 1
    printed = json.loads(capsys.readouterr().err)
    served = client.post("/v1/trajectories", json=body).json()
    assert printed["status"] == served["status"] == 422
    facts = {key: served[key] for key in ("s", "joint", "limit") if key in served}
    assert facts and {key: printed.get(key) for key in facts} == facts


def test_plan_reads_stdin(monkeypatch, capsys):
    monkeypatch.setattr("sys.stdin", io.StringIO(json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}})))
    assert main(["plan", "-"]) == 0
    assert json.loads(capsys.readouterr().out)["robot"] == "ur5"


def test_a_byte_order_mark_is_ignored_as_over_http(tmp_path, monkeypatch, capsys):
    """Editors on Windows save UTF-8 with a byte order mark; the service ignores it, so does the CLI."""
    body = json.dumps({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}})
    request = tmp_path / "bom.json"
    request.write_bytes(b"\xef\xbb\xbf" + body.encode())
    assert main(["plan", str(request)]) == 0
    monkeypatch.setattr("sys.stdin", io.StringIO("\ufeff" + body))
    assert main(["plan", "-"]) == 0
    assert [json.loads(line)["robot"] for line in capsys.readouterr().out.splitlines() if line.startswith("{")] == ["ur5", "ur5"]


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


# --- compare and plot: trajectory bodies, tables, overlays; help -----------------------------

SPLINE = ROOT / "examples" / "ur5_spline.json"


def _compared(capsys, *args) -> list[dict]:
    assert main(["compare", *args]) == 0
    return json.loads(capsys.readouterr().out)["results"]


def test_compare_takes_a_trajectory_body_under_methods(capsys):
    """The body's path and limits timed by each method: phase_plane's duration is the plan's."""
    results = _compared(capsys, str(SPLINE), "--methods", "phase_plane, quintic")
    assert [r["method"] for r in results] == ["phase_plane", "quintic"]
    assert main(["plan", str(SPLINE)]) == 0
    planned = json.loads(capsys.readouterr().out)
    assert results[0]["duration"] == pytest.approx(planned["duration"], rel=1e-12)
    assert results[0]["peak_utilization"] == planned["peak_utilization"]
    assert results[1]["duration"] > results[0]["duration"]  # the time-optimal one is the shorter


def test_compare_without_methods_runs_the_bodys_method_and_the_defaults(capsys, tmp_path):
    assert [r["method"] for r in _compared(capsys, str(SPLINE))] == ["phase_plane", "toppra", "quintic"]
    body = json.loads(SPLINE.read_text())
    body["timing"]["method"] = "cubic"
    request = tmp_path / "cubic.json"
    request.write_text(json.dumps(body))
    assert [r["method"] for r in _compared(capsys, str(request))] == ["cubic", "phase_plane", "toppra", "quintic"]
    from toptraj.service.commands import compare_body

    free = json.loads(compare_body((ROOT / "examples" / "geering_free_motion.json").read_text()))
    assert free["methods"] == ["collocation", "search"] and "output" not in free and free["path"]["kind"] == "free"


def test_methods_replace_those_of_a_compare_body(capsys):
    assert [r["method"] for r in _compared(capsys, str(ROOT / "examples" / "compare_methods.json"), "--methods", "quintic")] == ["quintic"]


def test_an_unknown_method_is_refused_naming_the_choices(capsys):
    assert main(["compare", str(SPLINE), "--methods", "phase_plane,fastest"]) == 1
    problem = json.loads(capsys.readouterr().err)
    assert problem["status"] == 422 and "methods" in problem["detail"] and "toppra" in problem["detail"]


def test_the_table_shows_each_method_against_the_fastest():
    from toptraj.service.compare_table import compare_table

    answer = {"results": [
        {"method": "quintic", "duration": 3.0, "peak_utilization": {"velocity": [0.5, 0.9], "torque": [1.002, 0.1]},
         "solve_ms": 1.25, "warnings": ["a", "b"]},
        {"method": "phase_plane", "duration": 1.5, "peak_utilization": {"velocity": [1.0, 0.2], "acceleration": [0.7, 0.3]},
         "solve_ms": 12.0, "warnings": []},
        {"method": "ruckig", "error": {"status": 422, "title": "Invalid request", "detail": "ruckig cannot limit torque"}},
    ]}
    lines = compare_table(answer).splitlines()
    assert lines[0].split() == ["method", "duration", "(s)", "×", "fastest", "peak", "utilization", "warnings", "solve", "(ms)"]
    assert lines[1].split() == ["quintic", "3.0000", "2.000", "1.0020", "torque", "2", "1.2"]
    assert lines[2].split() == ["phase_plane", "1.5000", "1.000", "1.0000", "velocity", "0", "12.0"]
    assert lines[3].split() == ["ruckig", "failed:", "422", "Invalid", "request"]
    assert lines[4] == "ruckig: ruckig cannot limit torque"
    assert "held within 0.5 %" in "\n".join(lines[5:])  # the promise of the limits


def test_compare_prints_a_table_on_a_terminal_and_json_when_piped_or_asked(monkeypatch, capsys):
    import pty
    import select

    command = [sys.executable, "-m", "toptraj.service.cli", "compare", str(SPLINE), "--methods", "phase_plane,quintic"]
    leader, follower = pty.openpty()
    with subprocess.Popen(command, cwd=ROOT, stdout=follower, stderr=subprocess.PIPE) as process:
        os.close(follower)
        printed = b""
        while True:
            assert select.select([leader], [], [], 120)[0], "no output for 120 s"
            try:
                chunk = os.read(leader, 65536)
            except OSError:  # the terminal closed with the process
                break
            if not chunk:
                break
            printed += chunk
        assert process.wait(timeout=120) == 0, process.stderr.read() if process.stderr else ""
    os.close(leader)
    lines = printed.decode().splitlines()
    assert lines[0].split()[:3] == ["method", "duration", "(s)"]
    assert lines[1].split()[0] == "phase_plane" and lines[2].split()[0] == "quintic" and lines[1].split()[2] == "1.000"
    assert main(["compare", str(SPLINE), "--methods", "quintic"]) == 0  # JSON into a pipe or a file (the capture)
    assert json.loads(capsys.readouterr().out)["results"][0]["method"] == "quintic"
    monkeypatch.setattr("sys.stdout.isatty", lambda: True)
    assert main(["compare", str(SPLINE), "--methods", "quintic", "--json"]) == 0  # JSON when asked, on a terminal too
    assert json.loads(capsys.readouterr().out)["results"][0]["method"] == "quintic"


def test_plot_draws_the_methods_of_a_comparison_over_each_other(tmp_path):
    out = tmp_path / "compare.html"
    body = json.loads((ROOT / "examples" / "compare_methods.json").read_text())
    assert main(["plot", str(ROOT / "examples" / "compare_methods.json"), "-o", str(out)]) == 0
    page = out.read_text()
    assert page.count("Plotly.newPlot") == 2 and "Phase plane, every method" in page and "use over time" in page
    for method in body["methods"]:  # a curve of each method in both figures, and a row of the table
        assert page.count(f'"name":"{method}"') == 4 and f"\n{method} " in page
    spline = tmp_path / "spline.html"
    assert main(["plot", str(SPLINE), "--methods", "phase_plane,quintic", "-o", str(spline)]) == 0
    assert spline.read_text().count('"name":"quintic"') == 4


@pytest.mark.parametrize("command", [[], ["serve"], ["plan"], ["compare"], ["plot"], ["batch"]])
def test_help_is_plain_text(command, capsys):
    """No markup (``literal``, `code`, :role:) nor module names in what --help prints."""
    with pytest.raises(SystemExit) as done:
        main([*command, "--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith("usage: toptraj")
    assert "`" not in text and ":class:" not in text and ":func:" not in text
    assert re.search(r"\b(service|planners|robots|client)\.[a-z_]", text) is None, text


def test_compare_of_a_body_leaves_out_the_default_methods_that_do_not_serve_its_timing(capsys):
    """A jerk-limited body is compared with the defaults that hold a jerk limit, a weighted one
    alone: each method left out is named with the setting it does not serve, instead of rows
    that all fail."""
    assert main(["compare", str(ROOT / "examples" / "ur5_jerk_limited.json"), "--json"]) == 0
    captured = capsys.readouterr()
    results = json.loads(captured.out)["results"]
    assert [row["method"] for row in results] == ["jerk_limited", "quintic"] and all("error" not in row for row in results)
    assert captured.err == (
        "toptraj compare: left out phase_plane (it does not serve timing.constraints 'jerk'); toppra (it does not serve "
        "timing.constraints 'jerk'); --methods names the methods to run\n"
    )
    assert main(["compare", str(ROOT / "examples" / "ur5_jerk_limited.json"), "--json", "--methods", "phase_plane"]) == 1
    named = capsys.readouterr()
    assert "error" in json.loads(named.out)["results"][0]  # what is named runs, and says why it fails
    assert named.err == "toptraj compare: every method failed (each one's error is in the comparison)\n"
