"""``toptraj serve --workers N``: N server processes on one port, each with its own app and
model cache over the one durable upload store; an upload, a deletion or a replacement made
through one process is what every other process serves next."""

from __future__ import annotations

import asyncio
import hashlib
import http.client
import json
import os
import socket
import sys

import psutil
import pytest

from tests.live_server import LiveServer
from tests.service.test_upload_store import PLAN, app_client, arm
from toptraj.robots.store import UploadStore
from toptraj.service.cli import APP_FACTORY, main, plan_threads_per_process
from toptraj.service.serving import LOOP, SWITCH_INTERVAL_S, BalancedEventLoop, new_event_loop, open_connections


def test_serve_runs_the_app_factory_in_one_process_per_core_by_default(monkeypatch):
    calls = []
    monkeypatch.setattr("uvicorn.run", lambda app, **options: calls.append((app, options)))
    monkeypatch.delenv("TOPTRAJ_PLAN_WORKERS", raising=False)
    assert main(["serve"]) == 0
    app, options = calls[-1]
    assert app == APP_FACTORY == "toptraj.service.app:create_app" and options["factory"] is True
    assert options["loop"] == LOOP == "toptraj.service.serving:new_server_loop"
    assert (options["host"], options["port"], options["workers"]) == ("127.0.0.1", 8000, os.cpu_count())
    assert os.environ["TOPTRAJ_PLAN_WORKERS"] == str(plan_threads_per_process(os.cpu_count()))

    monkeypatch.delenv("TOPTRAJ_PLAN_WORKERS")
    assert main(["serve", "--workers", "1", "--port", "8123"]) == 0
    assert (calls[-1][1]["workers"], calls[-1][1]["port"]) == (1, 8123)
    assert os.environ["TOPTRAJ_PLAN_WORKERS"] == str(os.cpu_count() or 1)

    monkeypatch.setenv("TOPTRAJ_PLAN_WORKERS", "3")  # an explicit setting wins
    assert main(["serve", "--workers", "4"]) == 0
    assert os.environ["TOPTRAJ_PLAN_WORKERS"] == "3"


def test_serve_refuses_fewer_than_one_worker(monkeypatch, capsys):
    monkeypatch.setattr("uvicorn.run", lambda *args, **options: pytest.fail("must not serve"))
    assert main(["serve", "--workers", "0"]) == 2
    assert "--workers must be at least 1" in capsys.readouterr().err


@pytest.mark.parametrize(("workers", "cores", "threads"), [(1, 2, 2), (2, 2, 1), (4, 2, 1), (2, 8, 4), (3, 8, 2)])
def test_each_process_plans_on_its_share_of_the_cores(workers, cores, threads):
    assert plan_threads_per_process(workers, cores) == threads


class _Echo(asyncio.Protocol):
    def connection_made(self, transport):
        self.transport = transport

    def data_received(self, data):
        self.transport.write(data)


async def _serve_on_a_given_socket() -> None:
    loop = asyncio.get_running_loop()
    listening = socket.socket()
    listening.bind(("127.0.0.1", 0))
    server = await loop.create_server(_Echo, sock=listening, backlog=16)
    assert server.is_serving()
    clients = [await asyncio.open_connection(*listening.getsockname()) for _ in range(3)]
    for k, (reader, writer) in enumerate(clients):
        writer.write(b"ping %d" % k)
        assert await reader.readexactly(6) == b"ping %d" % k
    assert open_connections() == 3  # what a planning asks before a try on the loop
    server.close()
    await server.wait_closed()
    assert not server.is_serving() and listening.fileno() == -1
    reader, writer = clients[0]  # accepted connections outlive the server
    writer.write(b"still!")
    assert await reader.readexactly(6) == b"still!"
    for _, writer in clients:
        writer.close()
        await writer.wait_closed()
    for _ in range(100):
        if open_connections() == 0:
            break
        await asyncio.sleep(0.01)
    assert open_connections() == 0


def test_the_balanced_loop_serves_a_shared_socket_and_stops_at_close():
    with asyncio.Runner(loop_factory=BalancedEventLoop) as runner:
        runner.run(_serve_on_a_given_socket())


def test_a_server_process_switches_threads_every_millisecond():
    before = sys.getswitchinterval()
    try:
        loop = new_event_loop()
        loop.close()
        assert isinstance(loop, BalancedEventLoop) and sys.getswitchinterval() == pytest.approx(SWITCH_INTERVAL_S)
    finally:
        sys.setswitchinterval(before)


def test_two_apps_on_one_data_directory_serve_each_others_uploads(tmp_path):
    with app_client(tmp_path) as first, app_client(tmp_path) as second:
        assert first.post("/v1/robots", json={"name": "shared_arm", "urdf": arm(5.0)}).status_code == 201
        planned = second.post("/v1/trajectories", json={"robot": "shared_arm", **PLAN})
        assert planned.status_code == 200, planned.text
        weak = planned.json()["duration"]
        assert first.delete("/v1/robots/shared_arm").status_code == 204
        assert second.post("/v1/trajectories", json={"robot": "shared_arm", **PLAN}).status_code == 404
        assert first.post("/v1/robots", json={"name": "shared_arm", "urdf": arm(9.0)}).status_code == 201
        assert second.get("/v1/robots/shared_arm").json()["limits"]["torque"] == [9.0, 9.0]
        strong = second.post("/v1/trajectories", json={"robot": "shared_arm", **PLAN}).json()["duration"]
        assert strong < weak  # the stronger arm's model, not the cached weaker one


def test_a_cached_model_never_outlives_a_change_another_process_made(tmp_path):
    """Another process writes to the store without touching this process's model cache: the
    next load must serve what the store holds now."""
    other_process = UploadStore(tmp_path)
    with app_client(tmp_path) as client:
        assert client.post("/v1/robots", json={"name": "arm_a", "urdf": arm(5.0)}).status_code == 201
        assert client.get("/v1/robots/arm_a").json()["limits"]["torque"] == [5.0, 5.0]  # cached here
        assert other_process.delete("arm_a")
        assert client.get("/v1/robots/arm_a").status_code == 404
        assert client.post("/v1/trajectories", json={"robot": "arm_a", **PLAN}).status_code == 404
        text = arm(9.0)
        other_process.put("arm_a", hashlib.sha256(text.encode()).hexdigest(), text, 2)
        assert client.get("/v1/robots/arm_a").json()["limits"]["torque"] == [9.0, 9.0]


class _Pinned:
    """A keep-alive connection, and the server process that accepted it."""

    def __init__(self, server: LiveServer):
        self.connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=120)
        assert self.call("GET", "/health")[0] == 200  # accepted by now
        self.pid = _owner(server, self.connection.sock.getsockname()[1])

    def call(self, method: str, path: str, body: dict | None = None) -> tuple[int, dict]:
        payload = None if body is None else json.dumps(body).encode()
        self.connection.request(method, path, body=payload, headers={"content-type": "application/json"})
        response = self.connection.getresponse()
        data = response.read()
        return response.status, (json.loads(data) if data else {})


def _owner(server: LiveServer, local_port: int) -> int:
    """The server process holding the connection whose client end is ``local_port``."""
    owners = [
        pid
        for pid in server.serving_pids()
        if any(c.raddr and c.raddr.port == local_port for c in psutil.Process(pid).net_connections(kind="tcp"))
    ]
    assert len(owners) == 1, owners
    return owners[0]


def _one_connection_per_process(server: LiveServer, tries: int = 64) -> dict[int, _Pinned]:
    pinned: dict[int, _Pinned] = {}
    spare = []
    for _ in range(tries):
        connection = _Pinned(server)
        if connection.pid in pinned:
            spare.append(connection)  # kept open, so that the next one may land elsewhere
        else:
            pinned[connection.pid] = connection
        if len(pinned) == server.workers:
            break
    for connection in spare:
        connection.connection.close()
    assert len(pinned) == server.workers, f"{tries} connections all went to {list(pinned)}"
    return pinned


@pytest.fixture(scope="module")
def two_workers(tmp_path_factory):
    """``toptraj serve --workers 2`` on a data directory of its own."""
    data_dir = tmp_path_factory.mktemp("data")
    with LiveServer(workers=2, TOPTRAJ_DATA_DIR=str(data_dir), TOPTRAJ_PRELOAD_ROBOTS="false") as server:
        yield server


def test_every_worker_process_serves_what_another_one_uploaded_deleted_or_replaced(two_workers):
    server: LiveServer = two_workers
    a, b = _one_connection_per_process(server).values()
    assert a.pid != b.pid
    assert a.call("POST", "/v1/robots", {"name": "shared_arm", "urdf": arm(5.0)})[0] == 201
    assert b.call("GET", "/v1/robots/shared_arm")[1]["limits"]["torque"] == [5.0, 5.0]
    status, planned = b.call("POST", "/v1/trajectories", {"robot": "shared_arm", **PLAN})
    assert status == 200, planned
    assert a.call("POST", "/v1/trajectories", {"robot": "shared_arm", **PLAN})[1]["duration"] == planned["duration"]
    # both processes hold the model now; a deletion through one is seen by the other
    assert a.call("DELETE", "/v1/robots/shared_arm")[0] == 204
    assert b.call("POST", "/v1/trajectories", {"robot": "shared_arm", **PLAN})[0] == 404
    assert b.call("GET", "/v1/robots/shared_arm")[0] == 404
    # another text under the same name, uploaded through the other process
    assert b.call("POST", "/v1/robots", {"name": "shared_arm", "urdf": arm(9.0)})[0] == 201
    status, stronger = a.call("POST", "/v1/trajectories", {"robot": "shared_arm", **PLAN})
    assert status == 200 and stronger["duration"] < planned["duration"]
    assert b.call("POST", "/v1/trajectories", {"robot": "shared_arm", **PLAN})[1]["duration"] == stronger["duration"]
    assert {row["name"] for row in a.call("GET", "/v1/robots")[1]} >= {"shared_arm"}
    # fresh connections, wherever they land: every plan is served, then every plan is a 404
    for expected in (200, 404):
        if expected == 404:
            assert a.call("DELETE", "/v1/robots/shared_arm")[0] == 204
        for _ in range(8):
            assert server.request("POST", "/v1/trajectories", {"robot": "shared_arm", **PLAN})[0] == expected
    for pinned in (a, b):
        pinned.connection.close()


def _burst(server: LiveServer, clients: int) -> list[int]:
    """Open ``clients`` connections at once, send ``GET /health`` on each, and return the
    process that holds each connection (all still open)."""
    connections = [socket.create_connection(("127.0.0.1", server.port), timeout=60) for _ in range(clients)]
    try:
        for connection in connections:
            connection.sendall(b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        for connection in connections:
            assert connection.recv(4096).startswith(b"HTTP/1.1 200")
        return [_owner(server, connection.getsockname()[1]) for connection in connections]
    finally:
        for connection in connections:
            connection.close()


def test_connections_opened_at_once_spread_over_the_processes(two_workers):
    """Four clients connecting together keep both processes (both cores) busy: the event
    loop's own accept loop gave all four to one process in 14 to 19 of 30 such bursts on a
    loaded 2-core machine, the balanced loop (``toptraj.service.serving``) in none of 60."""
    spread = [len(set(_burst(two_workers, 4))) == 2 for _ in range(5)]
    assert sum(spread) >= 4, spread
