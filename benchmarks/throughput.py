"""Throughput of ``toptraj serve --workers N`` over loopback, and ``/health`` under full load.

Starts one server per worker count (by default the number of cores and 1, each on its own free
port) and, in interleaved rounds, loads each with 1, 4 and 16 concurrent clients sending the
typical request (ur5, 4 spline waypoints, velocity + acceleration + torque, ``phase_plane``,
``output.dt`` 0.01) over keep-alive connections for ``--seconds`` each. During the 16-client load a
prober opens a new connection every 25 ms and times ``GET /health`` (connect, request, answer).

The load comes from a separate process (this script with ``--load``): one asyncio event loop,
raw HTTP/1.1 on ``asyncio`` streams, bodies counted and checked but not parsed, so that the
client costs little next to the server; its CPU time is measured and printed, as are the CPU
time of each server process (how the connections spread over the workers) and that of the rest
of the machine (``--quiet-below`` waits for the rest of a shared machine to calm down before each
phase). Printed per worker count, medians over the rounds: requests/s, p50 / p99
latency, requests answered 503 (every worker busy and its queue full; the client then waits
``Retry-After`` as a polite client does), the ratio rps(4 clients) / (N x rps(1 client)) against
the 0.8 target, and /health p50 / p99 during the 16-client load.

    python benchmarks/throughput.py [--workers 2,1] [--rounds 3] [--seconds 15] [--quiet-below 0.3]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import socket
import statistics
import subprocess
import sys
import time

import numpy as np
import psutil

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
UR5 = [
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
]
TYPICAL = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": UR5, "interpolation": "spline"},
    "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
    "output": {"dt": 0.01},
}
TARGET = 0.8
HEALTH_PERIOD_S = 0.025


# --- the load generator (runs in its own process) -------------------------------------------


async def _read_response(reader: asyncio.StreamReader) -> tuple[int, dict[str, str], bytes]:
    """One HTTP/1.1 response: status, lower-cased headers, body (Content-Length or chunked)."""
    head = await reader.readuntil(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    status = int(lines[0].split(" ", 2)[1])
    headers = {}
    for line in lines[1:]:
        if line:
            key, _, value = line.partition(":")
            headers[key.strip().lower()] = value.strip()
    if "content-length" in headers:
        body = await reader.readexactly(int(headers["content-length"]))
    elif headers.get("transfer-encoding") == "chunked":
        parts = []
        while True:
            size = int((await reader.readuntil(b"\r\n")).split(b";")[0], 16)
            parts.append(await reader.readexactly(size + 2))
            if size == 0:
                break
        body = b"".join(part[:-2] for part in parts)
    else:
        body = b""
    return status, headers, body


def _request(method: str, path: str, body: bytes = b"") -> bytes:
    head = f"{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
    return (head + f"Content-Length: {len(body)}\r\n\r\n").encode() + body


async def _client(port: int, payload: bytes, stop: float, window: tuple[float, float], record: dict) -> None:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    try:
        while time.perf_counter() < stop:
            started = time.perf_counter()
            writer.write(payload)
            status, headers, body = await _read_response(reader)
            ended = time.perf_counter()
            in_window = window[0] <= started and ended <= window[1]
            if status == 200:
                if not body.startswith(b'{"robot":"ur5"'):
                    raise RuntimeError(f"unexpected body: {body[:200]!r}")
                if in_window:
                    record["latency"].append(ended - started)
            elif status == 503:
                if in_window:
                    record["busy"] += 1
                await asyncio.sleep(min(float(headers.get("retry-after", "1")), 5.0))
            else:
                raise RuntimeError(f"HTTP {status}: {body[:300]!r}")
            if window[0] <= ended <= window[1]:
                record["done"] += status == 200
    finally:
        writer.close()


async def _health_prober(port: int, stop: float, window: tuple[float, float], latencies: list) -> None:
    probe = _request("GET", "/health")
    while time.perf_counter() < stop:
        started = time.perf_counter()
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        writer.write(probe)
        status, _, body = await _read_response(reader)
        ended = time.perf_counter()
        writer.close()
        if status != 200 or body != b'{"status":"ok"}':
            raise RuntimeError(f"/health answered {status}: {body[:200]!r}")
        if window[0] <= started and ended <= window[1]:
            latencies.append(ended - started)
        await asyncio.sleep(max(0.0, HEALTH_PERIOD_S - (ended - started)))


async def _load(port: int, clients: int, seconds: float, settle_s: float, health: bool) -> dict:
    payload = _request("POST", "/v1/trajectories", json.dumps(TYPICAL).encode())
    now = time.perf_counter()
    window = (now + settle_s, now + settle_s + seconds)
    record = {"latency": [], "busy": 0, "done": 0}
    health_latency: list[float] = []
    tasks = [_client(port, payload, window[1], window, record) for _ in range(clients)]
    if health:
        tasks.append(_health_prober(port, window[1], window, health_latency))
    cpu_before, wall_before = time.process_time(), time.perf_counter()
    await asyncio.gather(*tasks)
    cpu, wall = time.process_time() - cpu_before, time.perf_counter() - wall_before
    return {
        "rps": record["done"] / seconds,
        "latency_s": record["latency"],
        "busy": record["busy"],
        "health_s": health_latency,
        "client_cpu_share": cpu / wall,
    }


def _load_main(args) -> int:
    result = asyncio.run(_load(args.port, args.clients, args.seconds, args.settle, args.health))
    json.dump(result, sys.stdout)
    return 0


# --- the driver --------------------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class Server:
    """``toptraj serve --workers N`` on a free port."""

    def __init__(self, workers: int, env: dict[str, str]):
        self.workers = workers
        self.port = _free_port()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(self.port), "--workers", str(workers)],
            cwd=ROOT,
            env={**os.environ, "PYTHONPATH": ROOT, **env},
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def wait_until_up(self, timeout_s: float = 180.0) -> None:
        import http.client

        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if self.process.poll() is not None:
                raise RuntimeError(f"the server with {self.workers} workers exited ({self.process.returncode})")
            try:
                connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=2)
                connection.request("GET", "/health")
                if connection.getresponse().status == 200 and len(self.serving_processes()) == self.workers:
                    return
            except OSError:
                pass
            time.sleep(0.3)
        raise RuntimeError(f"the server with {self.workers} workers did not come up")

    def serving_processes(self) -> list[psutil.Process]:
        """The processes that answer requests: uvicorn's spawned workers, or the server itself."""
        root = psutil.Process(self.process.pid)
        if self.workers == 1:
            return [root]
        return [child for child in root.children() if "spawn_main" in " ".join(child.cmdline())]

    def cpu_seconds(self) -> list[float]:
        """CPU time of each serving process and everything under it (its fork server and the
        worker processes it started)."""
        totals = []
        for process in self.serving_processes():
            total = 0.0
            for member in [process, *process.children(recursive=True)]:
                try:
                    times = member.cpu_times()
                except psutil.NoSuchProcess:
                    continue
                total += times.user + times.system + times.children_user + times.children_system
            totals.append(total)
        return totals

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def _phase(server: Server, clients: int, seconds: float, settle_s: float, health: bool) -> dict:
    """One load phase from a fresh load-generator process; adds the server's CPU per process and
    the CPU the rest of the machine used, both in cores (CPU-s per s of the phase)."""
    command = [sys.executable, os.path.abspath(__file__), "--load", "--port", str(server.port)]
    command += ["--clients", str(clients), "--seconds", str(seconds), "--settle", str(settle_s)]
    if health:
        command.append("--health")
    machine_before, server_before, wall_before = psutil.cpu_times(), server.cpu_seconds(), time.perf_counter()
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - wall_before
    machine_after, server_after = psutil.cpu_times(), server.cpu_seconds()
    if done.returncode != 0:
        raise RuntimeError(f"the load generator failed: {done.stderr[-2000:]}")
    result = json.loads(done.stdout)
    busy_machine = sum(
        getattr(machine_after, field) - getattr(machine_before, field) for field in ("user", "system", "nice", "irq", "softirq")
    )
    per_process = [(after - before) / wall for before, after in zip(server_before, server_after)]
    result["server_cores"] = per_process
    result["other_cores"] = max(0.0, busy_machine / wall - sum(per_process) - result["client_cpu_share"])
    return result


def _busy_cores(seconds: float, servers: list[Server]) -> float:
    """Cores the machine used over ``seconds``, outside the servers' processes."""
    machine_before, server_before = psutil.cpu_times(), sum(sum(server.cpu_seconds()) for server in servers)
    time.sleep(seconds)
    machine_after, server_after = psutil.cpu_times(), sum(sum(server.cpu_seconds()) for server in servers)
    busy = sum(getattr(machine_after, f) - getattr(machine_before, f) for f in ("user", "system", "nice", "irq", "softirq"))
    return max(0.0, busy - (server_after - server_before)) / seconds


def _wait_for_quiet(servers: list[Server], below: float, patience_s: float) -> float:
    """Wait (at most ``patience_s``) until the rest of the machine uses less than ``below``
    cores over 2 s; return the last reading."""
    give_up = time.monotonic() + patience_s
    while True:
        busy = _busy_cores(2.0, servers)
        if busy < below or time.monotonic() > give_up:
            return busy
        time.sleep(3.0)


def _ms(values: list[float], q: float) -> float:
    return float(np.percentile(values, q) * 1e3) if values else float("nan")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    cores = os.cpu_count() or 1
    parser.add_argument("--workers", default=f"{cores},1" if cores > 1 else "1", help="worker counts, comma separated")
    parser.add_argument("--clients", default="1,4,16", help="concurrent client counts, comma separated")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=15.0, help="measured seconds per phase")
    parser.add_argument("--settle", type=float, default=2.0, help="seconds of load before each measurement")
    parser.add_argument("--env", action="append", default=[], help="TOPTRAJ_X=value for the servers (repeatable)")
    parser.add_argument(
        "--quiet-below",
        type=float,
        default=None,
        help="before each phase, wait until the rest of the machine uses fewer cores than this (a shared machine)",
    )
    parser.add_argument("--patience", type=float, default=300.0, help="longest wait for --quiet-below, s")
    parser.add_argument("--load", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--port", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--health", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.load:
        args.clients = int(args.clients)
        return _load_main(args)

    workers = [int(n) for n in args.workers.split(",")]
    client_counts = [int(n) for n in args.clients.split(",")]
    env = dict(item.split("=", 1) for item in args.env)
    print(f"{cores} cores; servers with {workers} workers; {args.rounds} interleaved rounds of {args.seconds:g} s per phase")
    if env:
        print(f"server settings: {env}")
    servers = [Server(n, env) for n in workers]
    results: dict[tuple[int, int], list[dict]] = {}
    try:
        for server in servers:
            server.wait_until_up()
            _phase(server, max(client_counts), 5.0, 1.0, health=False)  # warm every worker
        for round_ in range(args.rounds):
            for server in servers:
                for clients in client_counts:
                    if args.quiet_below is not None:
                        _wait_for_quiet(servers, args.quiet_below, args.patience)
                    phase = _phase(server, clients, args.seconds, args.settle, health=clients == max(client_counts))
                    results.setdefault((server.workers, clients), []).append(phase)
                    print(
                        f"  round {round_ + 1}, N={server.workers}, {clients:2d} clients: {phase['rps']:6.1f} req/s, "
                        f"p50 {_ms(phase['latency_s'], 50):6.1f} ms, p99 {_ms(phase['latency_s'], 99):6.1f} ms, "
                        f"503s {phase['busy']}, server cores {' + '.join(f'{c:.2f}' for c in phase['server_cores'])}, "
                        f"client {phase['client_cpu_share']:.2f}, others {phase['other_cores']:.2f}",
                        flush=True,
                    )
    finally:
        for server in servers:
            server.stop()

    def median(n: int, clients: int, key) -> float:
        return statistics.median(key(phase) for phase in results[(n, clients)])

    print()
    print("medians over the rounds (latency percentiles per round, then the median of those)")
    header = f"{'N':>3s} {'clients':>7s} {'req/s':>7s} {'p50 ms':>7s} {'p99 ms':>7s} {'503s':>5s} "
    print(header + f"{'server cores':>14s} {'client cores':>12s} {'other cores':>11s}")
    for n in workers:
        for clients in client_counts:
            print(
                f"{n:3d} {clients:7d} {median(n, clients, lambda p: p['rps']):7.1f} "
                f"{median(n, clients, lambda p: _ms(p['latency_s'], 50)):7.1f} "
                f"{median(n, clients, lambda p: _ms(p['latency_s'], 99)):7.1f} "
                f"{median(n, clients, lambda p: p['busy']):5.0f} "
                f"{median(n, clients, lambda p: sum(p['server_cores'])):14.2f} "
                f"{median(n, clients, lambda p: p['client_cpu_share']):12.2f} "
                f"{median(n, clients, lambda p: p['other_cores']):11.2f}"
            )
    print()
    most = max(client_counts)
    for n in workers:
        if 1 in client_counts and 4 in client_counts:
            ratios = [four["rps"] / (n * one["rps"]) for one, four in zip(results[(n, 1)], results[(n, 4)])]
            verdict = "met" if statistics.median(ratios) >= TARGET else "NOT met"
            print(
                f"N={n}: rps(4 clients) / (N x rps(1 client)) = {statistics.median(ratios):.2f} "
                f"(rounds: {', '.join(f'{r:.2f}' for r in ratios)}; target >= {TARGET}: {verdict})"
            )
            # The ratio is (cores the server got at 4 clients / (N x cores at 1 client)) x
            # (requests per server CPU-second at 4 clients / the same at 1 client): the first
            # factor is what the machine gave (the load generator and other work share the
            # cores), the second what the server made of it.
            cores_got = [sum(four["server_cores"]) / (n * sum(one["server_cores"])) for one, four in zip(results[(n, 1)], results[(n, 4)])]
            per_cpu = [
                (four["rps"] / sum(four["server_cores"])) / (one["rps"] / sum(one["server_cores"]))
                for one, four in zip(results[(n, 1)], results[(n, 4)])
            ]
            print(
                f"       = cores the server got, 4 clients / (N x 1 client) {statistics.median(cores_got):.2f} "
                f"x requests per server CPU-second, 4 clients / 1 client {statistics.median(per_cpu):.2f}"
            )
        health = [p for p in results[(n, most)]]
        print(
            f"N={n}: /health during {most} clients: p50 {statistics.median(_ms(p['health_s'], 50) for p in health):.1f} ms, "
            f"p99 {statistics.median(_ms(p['health_s'], 99) for p in health):.1f} ms "
            f"(worst round p99 {max(_ms(p['health_s'], 99) for p in health):.1f} ms, "
            f"{sum(len(p['health_s']) for p in health)} probes; target < 50 ms)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
