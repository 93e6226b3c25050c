"""End-to-end latency of POST /v1/trajectories over loopback, for three request sizes.

Starts ``toptraj serve`` on a free local port, sends each request ``--repeat`` times over one
keep-alive connection after a warm-up, and prints p50 / p95 in milliseconds.

    python benchmarks/latency.py [--repeat 200]
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import socket
import subprocess
import sys
import time

import numpy as np

UR5_4 = [
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
]


def _requests() -> dict[str, dict]:
    rng = np.random.default_rng(7)
    panda_12 = np.clip(rng.normal(0.0, 0.6, (12, 7)) + [0, 0, 0, -1.6, 0, 1.8, 0], -1.5, 1.5)
    panda_12[:, 3] = np.clip(panda_12[:, 3], -3.0, -0.2)
    panda_12[:, 5] = np.clip(panda_12[:, 5], 0.0, 3.5)
    requests = {}
    for method in ("phase_plane", "toppra"):
        requests[f"small: ur5, 2 waypoints, torque, {method}"] = {
            "robot": "ur5",
            "path": {"kind": "waypoints", "waypoints": UR5_4[:2]},
            "timing": {"method": method, "constraints": ["torque"]},
        }
        requests[f"target: ur5, 4 waypoints, torque, {method}"] = {
            "robot": "ur5",
            "path": {"kind": "waypoints", "waypoints": UR5_4},
            "timing": {"method": method, "constraints": ["torque"]},
        }
        requests[f"large: panda, 12 wp, vel+acc+torque, {method}"] = {
            "robot": "panda",
            "path": {"kind": "waypoints", "waypoints": panda_12.tolist()},
            "timing": {"method": method, "constraints": ["velocity", "acceleration", "torque"]},
        }
    return requests


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _wait_for(port: int, timeout_s: float = 60.0) -> None:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        try:
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=2)
            connection.request("GET", "/health")
            if connection.getresponse().status == 200:
                return
        except OSError:
            time.sleep(0.2)
    raise RuntimeError("the server did not come up")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=200)
    args = parser.parse_args()
    port = _free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(port), "--workers", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={**os.environ},
    )
    try:
        _wait_for(port)
        connection = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
        print(f"{'request':50s} {'p50 ms':>8s} {'p95 ms':>8s} {'solve ms':>9s} {'duration s':>10s}")
        for label, body in _requests().items():
            payload = json.dumps(body).encode()
            times, solve = [], []
            for k in range(args.repeat + 5):
                started = time.perf_counter()
                connection.request("POST", "/v1/trajectories", payload, {"content-type": "application/json"})
                response = connection.getresponse()
                data = response.read()
                elapsed = (time.perf_counter() - started) * 1e3
                if response.status != 200:
                    raise RuntimeError(f"{label}: HTTP {response.status}: {data[:300]!r}")
                if k >= 5:
                    times.append(elapsed)
                    solve.append(json.loads(data)["solve_ms"])
            result = json.loads(data)
            print(
                f"{label:50s} {np.percentile(times, 50):8.1f} {np.percentile(times, 95):8.1f} "
                f"{np.median(solve):9.1f} {result['duration']:10.4f}"
            )
    finally:
        server.terminate()
        server.wait(timeout=10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
