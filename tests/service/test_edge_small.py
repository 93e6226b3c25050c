"""Small things at the edge say what to do: a path no route serves names the nearest route, a
body over the cap says how to send less, ``toptraj serve`` on a busy port says so before
starting anything, and a resumed batch with nothing left says that instead of a rate of nothing."""

from __future__ import annotations

import io
import json
import socket

from fastapi.testclient import TestClient

from toptraj.service.app import create_app
from toptraj.service.batches import run_batch
from toptraj.service.batches.runner import progress_bar
from toptraj.service.cli import main
from toptraj.service.settings import Settings


def test_a_path_no_route_serves_names_the_nearest_route_and_it_exists(client):
    answer = client.post("/v1/trajectory", json={})
    assert answer.status_code == 404
    assert answer.headers["content-type"] == "application/problem+json"
    assert answer.json()["detail"] == "no route at /v1/trajectory: did you mean /v1/trajectories?; the routes are listed at /docs"
    assert client.post("/v1/trajectories", json={}).status_code == 422  # the suggested route is there
    assert client.get("/docs").status_code == 200
    assert client.get("/nothing/like/it").json()["detail"] == "no route at /nothing/like/it; the routes are listed at /docs"


def test_a_body_over_the_cap_says_how_to_send_less(tmp_path):
    settings = Settings(preload_robots=False, data_dir=tmp_path, max_body_bytes=1000)
    with TestClient(create_app(settings)) as small:
        answer = small.post("/v1/trajectories", content=b"{" + b" " * 2000 + b"}", headers={"content-type": "application/json"})
    assert answer.status_code == 413
    detail = answer.json()["detail"]
    assert detail.startswith("the request body exceeds 1000 bytes: send fewer waypoints")
    assert "POST /v1/batches" in detail and "toptraj batch" in detail and "TOPTRAJ_MAX_BODY_BYTES" in detail


def test_serve_on_a_busy_port_says_so_and_which_option_to_pass(capsys):
    with socket.socket() as busy:
        busy.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert main(["serve", "--host", "127.0.0.1", "--port", str(port)]) == 3
    err = capsys.readouterr().err
    assert f"port {port} is in use (another server?): pass --port N, e.g. --port " in err
    assert "server process(es)" not in err


def test_a_resumed_batch_with_nothing_left_says_so(tmp_path):
    requests, output = tmp_path / "requests.jsonl", tmp_path / "results.jsonl"
    requests.write_text("{'robot': 'ur5'}\n")  # answered without planning: a 422 line
    run_batch(requests, output, pool=lambda: None)
    stream = io.StringIO()
    report = run_batch(requests, output, pool=lambda: None, progress=progress_bar(stream))
    assert report.skipped == 1
    assert stream.getvalue() == "nothing left to do: every request already has its result in the output\n"
    assert json.loads(output.read_text())["status"] == 422


def test_the_progress_line_leaves_out_the_time_left_until_there_is_a_rate():
    stream = io.StringIO()
    progress_bar(stream)(0, 5, 0.0)
    assert stream.getvalue() == "\r0/5 requests, 0.0/s   "


def test_an_upload_over_the_body_cap_is_told_about_its_urdf_not_waypoints(tmp_path):
    settings = Settings(preload_robots=False, data_dir=tmp_path, max_body_bytes=1000)
    with TestClient(create_app(settings)) as small:
        answer = small.post("/v1/robots", json={"name": "big", "urdf": "<robot>" + " " * 2000 + "</robot>"})
    assert answer.status_code == 413
    detail = answer.json()["detail"]
    assert detail.startswith("the request body exceeds 1000 bytes: leave out of the URDF what planning does not read"), detail
    assert "waypoints" not in detail and "TOPTRAJ_MAX_BODY_BYTES" in detail


def test_a_number_of_thousands_of_digits_is_a_422_saying_so(client):
    body = '{"robot": "ur5", "path": {"waypoints": [[0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, ' + "9" * 5000 + "]]}}"
    answer = client.post("/v1/trajectories", content=body, headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text[:300]
    assert answer.json()["detail"].startswith("body: a number has more than 4300 digits")


def test_a_cell_or_a_skeleton_over_the_body_cap_is_advised_what_it_holds(tmp_path):
    settings = Settings(preload_robots=False, data_dir=tmp_path, max_body_bytes=1000)
    with TestClient(create_app(settings)) as small:
        cell = small.post("/v1/cells", content=b"{" + b" " * 2000 + b"}", headers={"content-type": "application/json"})
        skeleton = small.post("/v1/robots/ur5/skeleton", content=b"{" + b" " * 2000 + b"}", headers={"content-type": "application/json"})
    assert cell.status_code == skeleton.status_code == 413
    assert "give each arm fewer waypoints" in cell.json()["detail"] and "batch" not in cell.json()["detail"]
    assert "send fewer configurations in q" in skeleton.json()["detail"] and "waypoints" not in skeleton.json()["detail"]
