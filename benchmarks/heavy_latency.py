"""The typical request's latency while two heavy plannings run past their budget, beside its
latency on the idle server, in one run (the timing study behind
``tests/service/test_heavy_admission.py``, which checks only events).

Starts ``toptraj serve`` (2 workers, a 3 s planning budget) on a free local port; times
``--repeat`` typical requests (ur5, 4 spline waypoints, velocity + acceleration + torque,
phase_plane) on the idle server, then the same requests from two clients while two default ur5
searches around a box (about 10 s of work each) run until their 504; prints p50 and p99 of both
and their ratio (goal: p99 under load below 1 s, as the admission of heavy work promises).

    python benchmarks/heavy_latency.py [--repeat 100]
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import subprocess
import sys
import threading
import time

import numpy as np
from latency import UR5_4, _free_port, _wait_for

TYPICAL = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": UR5_4},
    "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
}
SEARCH = {
    "robot": "ur5",
    "path": {
        "kind": "free",
        "start": [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0],
        "goal": [1.0, -1.2, 1.5, -1.9, -1.57, 0.0],
        "obstacles": [{"kind": "box", "center": [0.626, 0.109, 0.29], "size": [0.15, 0.15, 0.15]}],
        "clearance": 0.02,
    },
    "timing": {"method": "search"},
}


def _post(port: int, body: dict) -> tuple[int, float]:
    """(status, seconds) of one POST /v1/trajectories on a connection of its own."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
    started = time.perf_counter()
    connection.request("POST", "/v1/trajectories", json.dumps(body).encode(), {"content-type": "application/json"})
    response = connection.getresponse()
    response.read()
    return response.status, time.perf_counter() - started


def _under_searches(port: int) -> tuple[list[float], list[int]]:
    """Latencies (s) of typical requests sent by two clients while two searches run, and the
    searches' statuses."""
    statuses: list[int] = []
    latencies: list[float] = []
    done = threading.Event()

    def search() -> None:
        statuses.append(_post(port, SEARCH)[0])

    def stream() -> None:
        while not done.is_set():
            status, seconds = _post(port, TYPICAL)
            if status != 200:
                raise RuntimeError(f"a typical request answered {status}")
            latencies.append(seconds)

    searches = [threading.Thread(target=search) for _ in range(2)]
    streams = [threading.Thread(target=stream) for _ in range(2)]
    for thread in (*streams, *searches):
        thread.start()
    for thread in searches:
        thread.join()
    done.set()
    for thread in streams:
        thread.join()
    return latencies, statuses


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=100)
    args = parser.parse_args()
    port = _free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(port), "--workers", "2"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={**os.environ, "TOPTRAJ_PLAN_BUDGET_S": "3.0"},
    )
    try:
        _wait_for(port)
        idle = [_post(port, TYPICAL)[1] for _ in range(args.repeat + 20)][20:]  # both workers warm
        loaded, statuses = _under_searches(port)
        for label, times in (("idle", idle), ("two searches running", loaded)):
            print(f"{label:22s} p50 {1e3 * np.percentile(times, 50):8.1f} ms   p99 {1e3 * np.percentile(times, 99):8.1f} ms   ({len(times)} requests)")
        ratio = np.percentile(loaded, 99) / np.percentile(idle, 99)
        print(f"p99 loaded / idle {ratio:.2f}x; p99 loaded {np.percentile(loaded, 99):.3f} s (goal < 1 s); searches answered {statuses}")
    finally:
        server.terminate()
        server.wait(timeout=10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
