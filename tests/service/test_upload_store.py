"""Uploads are durable (a restart or another process sees them), capped by count and bytes,
deletable, and cost a bounded number of built models in memory."""

from __future__ import annotations

import gc
import multiprocessing
import os
import socket
import subprocess
import sys
import time
import weakref
from pathlib import Path

import httpx
import pytest
from fastapi.testclient import TestClient

from tests.paths import ROOT
from toptraj import robots
from toptraj.robots.store import UploadStore
from toptraj.robots.uploads import cached_upload_count
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

REPO = ROOT


def arm(effort: float = 5.0, mass: float = 1.0) -> str:
    """A two-joint arm; distinct arguments give distinct texts."""
    inertial = f"""<inertial><origin xyz="0.2 0 0"/><mass value="{mass}"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>"""
    return f"""<robot name="two">
  <link name="base"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="{effort}" velocity="2"/>
  </joint>
  <link name="upper">{inertial}</link>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/><origin xyz="0.4 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="{effort}" velocity="2"/>
  </joint>
  <link name="fore">{inertial}</link>
</robot>"""


PLAN = {"path": {"waypoints": [[0.0, 0.0], [0.5, 0.3]]}, "timing": {"constraints": ["torque"]}}


def app_client(data_dir: Path, **settings) -> TestClient:
    return TestClient(create_app(Settings(preload_robots=False, data_dir=data_dir, **settings)))


def test_an_upload_survives_a_restart(tmp_path):
    with app_client(tmp_path) as first:
        assert first.post("/v1/robots", json={"name": "kept_arm", "urdf": arm()}).status_code == 201
        before = first.post("/v1/trajectories", json={"robot": "kept_arm", **PLAN}).json()["duration"]
    with app_client(tmp_path) as second:  # a new app starts with an empty model cache
        assert cached_upload_count() == 0
        assert second.get("/v1/robots/kept_arm").json()["limits"]["torque"] == [5.0, 5.0]
        planned = second.post("/v1/trajectories", json={"robot": "kept_arm", **PLAN})
        assert planned.status_code == 200 and planned.json()["duration"] == before
        assert {"name": "kept_arm", "dof": 2, "source": "upload"} in second.get("/v1/robots").json()


def test_delete_removes_an_upload(tmp_path):
    with app_client(tmp_path) as client:
        assert client.post("/v1/robots", json={"name": "gone_arm", "urdf": arm()}).status_code == 201
        assert client.get("/v1/robots/gone_arm").status_code == 200
        deleted = client.delete("/v1/robots/gone_arm")
        assert deleted.status_code == 204 and deleted.content == b""
        assert client.get("/v1/robots/gone_arm").status_code == 404
        assert client.post("/v1/trajectories", json={"robot": "gone_arm", **PLAN}).status_code == 404
        assert "gone_arm" not in [row["name"] for row in client.get("/v1/robots").json()]
        again = client.delete("/v1/robots/gone_arm")
        assert again.status_code == 404 and again.headers["content-type"] == "application/problem+json"
        catalog = client.delete("/v1/robots/ur5")
        assert catalog.status_code == 409 and "catalog" in catalog.json()["detail"]
        assert client.get("/v1/robots/ur5").status_code == 200
        # the name is free again, for any text
        assert client.post("/v1/robots", json={"name": "gone_arm", "urdf": arm(effort=7.0)}).status_code == 201
        assert client.get("/v1/robots/gone_arm").json()["limits"]["torque"] == [7.0, 7.0]
    assert robots.upload_store().usage().uploads == 1


def test_delete_is_declared_in_the_openapi(client):
    operation = client.get("/openapi.json").json()["paths"]["/v1/robots/{name}"]["delete"]
    assert set(operation["responses"]) >= {"204", "404", "409"}
    assert "application/problem+json" in operation["responses"]["409"]["content"]


def test_the_count_cap_gives_409_saying_how_to_free_space(tmp_path):
    with app_client(tmp_path, max_uploads=2) as client:
        for effort in (1.0, 2.0):
            assert client.post("/v1/robots", json={"urdf": arm(effort)}).status_code == 201
        full = client.post("/v1/robots", json={"name": "third", "urdf": arm(3.0)})
        assert full.status_code == 409, full.text
        assert full.json()["title"] == "Upload store full"
        assert "2 uploads" in full.json()["detail"] and "DELETE /v1/robots/" in full.json()["detail"]
        assert client.post("/v1/robots", json={"urdf": arm(1.0)}).status_code == 201  # already stored: fine
        first = client.get("/v1/robots").json()[-2]["name"]
        assert client.delete(f"/v1/robots/{first}").status_code == 204
        assert client.post("/v1/robots", json={"name": "third", "urdf": arm(3.0)}).status_code == 201


def test_the_byte_cap_gives_409(tmp_path):
    size = len(arm().encode())
    with app_client(tmp_path, max_upload_bytes=2 * size + 10) as client:
        assert client.post("/v1/robots", json={"name": "a1", "urdf": arm(1.0)}).status_code == 201
        assert client.post("/v1/robots", json={"name": "a2", "urdf": arm(2.0)}).status_code == 201
        assert client.post("/v1/robots", json={"name": "a1_again", "urdf": arm(1.0)}).status_code == 201  # text stored once
        full = client.post("/v1/robots", json={"name": "a3", "urdf": arm(3.0)})
        assert full.status_code == 409 and "bytes" in full.json()["detail"]


def test_a_name_differing_from_a_stored_one_only_in_case_is_refused_in_the_store_itself(tmp_path):
    """Checked inside the store's transaction too, so that two processes uploading ``Arm`` and
    ``arm`` at once cannot both store theirs."""
    from toptraj.robots.errors import RobotConflict

    store = UploadStore(tmp_path)
    assert store.put("Arm", "1" * 64, "text one", 1) and store.alike("ARM") == "Arm" and store.alike("Arm") is None
    with pytest.raises(RobotConflict, match="name 'arm' differs from the upload 'Arm' only in case"):
        store.put("arm", "2" * 64, "text two", 1)
    assert [upload.name for upload in store.uploads()] == ["Arm"]


def test_the_model_cache_stays_bounded(tmp_path):
    with app_client(tmp_path, upload_cache_size=2) as client:
        names = [client.post("/v1/robots", json={"urdf": arm(effort)}).json()["name"] for effort in (1.0, 2.0, 3.0, 4.0, 5.0)]
        assert cached_upload_count() == 2
        alive = []
        for name in names:
            robot = robots.load(name)
            assert robot.limits.torque[0] == float(names.index(name) + 1)
            alive.append(weakref.ref(robot))
            del robot
        gc.collect()
        assert sum(ref() is not None for ref in alive) == 2  # only the two most recent are kept
        assert cached_upload_count() == 2
        assert robots.load(names[-1]) is alive[-1]()  # a cached model is reused
        for name in names:  # an evicted model is rebuilt from the store
            assert client.get(f"/v1/robots/{name}").status_code == 200


def _put_many(data_dir: str, offset: int, results) -> None:
    store = UploadStore(data_dir, max_uploads=10)
    outcome = []
    for k in range(5):
        try:
            store.put(f"arm_{offset}_{k}", f"{offset:04d}{k:04d}" + "0" * 56, f"text {offset} {k}", 1)
            outcome.append("stored")
        except robots.UploadStoreFull:
            outcome.append("full")
    results.put(outcome)


@pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(), reason="needs fork")
def test_processes_writing_at_once_never_pass_the_cap(tmp_path):
    context = multiprocessing.get_context("fork")
    results = context.Queue()
    workers = [context.Process(target=_put_many, args=(str(tmp_path), offset, results)) for offset in range(4)]
    for worker in workers:
        worker.start()
    outcomes = [results.get(timeout=60) for _ in workers]
    for worker in workers:
        worker.join(timeout=60)
    assert sum(outcome.count("stored") for outcome in outcomes) == 10
    stored = UploadStore(tmp_path).uploads()
    usage = UploadStore(tmp_path).usage()
    assert len(stored) == usage.uploads == 10
    assert usage.bytes == sum(len(f"text {offset} {k}") for _, offset, k in (row.name.split("_") for row in stored))


def test_an_unwritable_data_directory_is_a_503_not_a_crash(tmp_path):
    not_a_directory = tmp_path / "file"
    not_a_directory.write_text("")
    with app_client(not_a_directory) as client:
        response = client.post("/v1/robots", json={"urdf": arm()})
        assert response.status_code == 503, response.text
        assert "data directory" in response.json()["detail"]
        assert client.get("/v1/robots/nope").status_code == 404


def test_reading_an_empty_store_creates_nothing(tmp_path):
    store = UploadStore(tmp_path / "never")
    assert store.uploads() == [] and store.digest("x") is None and store.delete("x") is False
    assert not (tmp_path / "never").exists()


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _start_server(data_dir: Path, port: int, log: Path) -> subprocess.Popen:
    env = {**os.environ, "TOPTRAJ_DATA_DIR": str(data_dir), "TOPTRAJ_PRELOAD_ROBOTS": "false", "PYTHONPATH": str(REPO)}
    with open(log, "wb") as output:
        process = subprocess.Popen(
            [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(port), "--workers", "1"],
            env=env,
            stdout=output,
            stderr=subprocess.STDOUT,
        )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        try:
            if httpx.get(f"http://127.0.0.1:{port}/health", timeout=1).status_code == 200:
                return process
        except httpx.TransportError:
            time.sleep(0.2)
    process.kill()
    raise RuntimeError(f"the server did not start: {log.read_text()[-2000:]}")


def test_a_second_process_sees_uploads_replacements_and_deletions(tmp_path):
    """A server process and this process on one data directory: each sees what the other
    stored (what a restart reads is what another process wrote), deleted or replaced."""
    port, data_dir = _free_port(), tmp_path / "data"
    server = _start_server(data_dir, port, tmp_path / "server.log")
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=60) as other, app_client(data_dir) as here:
            assert here.post("/v1/robots", json={"name": "from_here", "urdf": arm(5.0)}).status_code == 201
            assert other.get("/v1/robots/from_here").json()["limits"]["torque"] == [5.0, 5.0]
            assert other.post("/v1/robots", json={"name": "from_there", "urdf": arm(6.0)}).status_code == 201
            assert here.get("/v1/robots/from_there").json()["limits"]["torque"] == [6.0, 6.0]
            assert here.post("/v1/trajectories", json={"robot": "from_there", **PLAN}).status_code == 200
            # this process has from_here cached; the other deletes it and stores another text
            assert other.delete("/v1/robots/from_here").status_code == 204
            assert here.get("/v1/robots/from_here").status_code == 404
            assert other.post("/v1/robots", json={"name": "from_here", "urdf": arm(9.0)}).status_code == 201
            assert here.get("/v1/robots/from_here").json()["limits"]["torque"] == [9.0, 9.0]
            listed = {row["name"] for row in other.get("/v1/robots").json()}
            assert {"from_here", "from_there"} <= listed
    finally:
        server.terminate()
        server.wait(timeout=30)
