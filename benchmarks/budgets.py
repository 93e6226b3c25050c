"""Budgets and memory, measured on real servers over loopback.

1. Time to idle after a 504: a server with a 1.5 s budget (long enough for min_cost to reach its
   solver) gets one request per slow family (via points, min_cost at its largest grid, the IK of
   a long Cartesian polyline, collocation); after
   each 504, the CPU time of the server's process tree (worker processes included) is sampled
   every 100 ms for 2 s. Printed: CPU-s in those 2 s, and the end of the last 100 ms window
   (after the 504) in which the tree used more than 20 % of a core.
2. Memory per grid interval and joint of min_cost, jerk_limited, toppra and phase_plane: peak RSS
   growth of one inline solve (a fresh process per grid size), which the runner's memory
   admission uses (``bytes_per_interval_joint``); and the server's RSS before and after three
   min_cost requests at grid 4000.
3. /health while a large body is produced: a server with the default budget and body cap gets
   the request with the smallest output.dt that fits the cap; /health is polled meanwhile.

    python benchmarks/budgets.py [--skip idle,memory,health]
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import re
import socket
import subprocess
import sys
import threading
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

#: A 0.3 m x 0.2 m rectangle in the ur5's workspace, from the start pose of the end effector.
RECTANGLE = [[0.357, 0.191, 0.77], [0.357, 0.191, 0.47], [0.557, 0.191, 0.47], [0.557, 0.191, 0.77]]


def _slow_requests() -> dict[str, dict]:
    walk = (np.array(UR5[0]) + np.cumsum(np.random.default_rng(8).uniform(-0.15, 0.15, (40, 6)), axis=0)).round(4)
    return {
        "via points (40, quintic)": {
            "robot": "ur5",
            "path": {"kind": "waypoints", "interpolation": "via", "waypoints": walk.tolist()},
            "timing": {"method": "quintic", "constraints": ["velocity", "acceleration", "torque"]},
        },
        "min_cost, grid 4000": {
            "robot": "ur5", "path": {"waypoints": UR5}, "timing": {"method": "min_cost", "grid_points": 4000},
        },
        "cartesian polyline, 24 m": {
            "robot": "ur5",
            "path": {"kind": "cartesian", "start": UR5[0], "positions": [[0.557, 0.191, 0.77]] + RECTANGLE * 20},
            "timing": {"method": "phase_plane"},
        },
        "collocation, ur5": {
            "robot": "ur5",
            "path": {"kind": "free", "start": [0.0] * 6, "goal": [0.5] * 6},
            "timing": {"method": "collocation"},
        },
    }


class Server:
    """``toptraj serve`` on a free port with ``TOPTRAJ_*`` settings."""

    def __init__(self, **env: str):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            self.port = probe.getsockname()[1]
        self.process = subprocess.Popen(
            [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(self.port), "--workers", "1"],
            cwd=ROOT,
            env={**os.environ, **env},
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        end = time.monotonic() + 120
        while time.monotonic() < end:
            try:
                if self.request("GET", "/health", timeout=2)[0] == 200:
                    break
            except OSError:
                time.sleep(0.2)
        self.tree = psutil.Process(self.process.pid)

    def request(self, method, path, body=None, timeout=300):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout)
        try:
            connection.request(method, path, None if body is None else json.dumps(body).encode(), {"content-type": "application/json"})
            response = connection.getresponse()
            return response.status, response.read()
        finally:
            connection.close()

    def cpu_seconds(self) -> float:
        total = 0.0
        for process in [self.tree, *self.tree.children(recursive=True)]:
            try:
                times = process.cpu_times()
            except psutil.NoSuchProcess:
                continue
            total += times.user + times.system + times.children_user + times.children_system
        return total

    def rss_mb(self) -> tuple[float, float]:
        """RSS of the server process, and of the processes under it (the worker server), in MB."""
        others = 0.0
        for process in self.tree.children(recursive=True):
            try:
                others += process.memory_info().rss
            except psutil.NoSuchProcess:
                pass
        return self.tree.memory_info().rss / 2**20, others / 2**20

    def wait_until_idle(self, timeout_s: float = 300) -> None:
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            before = self.cpu_seconds()
            time.sleep(0.5)
            if self.cpu_seconds() - before < 0.05:
                return
        raise RuntimeError("the server did not come to rest")

    def close(self) -> None:
        self.process.terminate()
        self.process.wait(timeout=10)


def idle_after_504(budget_s: float) -> None:
    server = Server(TOPTRAJ_PLAN_BUDGET_S=str(budget_s), TOPTRAJ_PRELOAD_ROBOTS="false")
    try:
        server.request("GET", "/v1/robots/ur5")
        print(f"\nTime to idle after a 504 (budget {budget_s} s)")
        print(f"{'request':28s} {'status':>6s} {'answer s':>8s} {'CPU-s in 2 s after':>19s} {'last busy s':>11s}")
        for label, body in _slow_requests().items():
            server.wait_until_idle()
            started = time.monotonic()
            status, _ = server.request("POST", "/v1/trajectories", body)
            answered = time.monotonic()
            first = last = server.cpu_seconds()
            last_busy = 0.0
            while time.monotonic() - answered < 2.0:
                time.sleep(0.1)
                now = server.cpu_seconds()
                if now - last > 0.02:  # 20 % of a core over 100 ms (a clock tick is 10 ms)
                    last_busy = time.monotonic() - answered
                last = now
            print(f"{label:28s} {status:6d} {answered - started:8.2f} {last - first:19.3f} {last_busy:11.2f}")
    finally:
        server.close()


_PEAK = """
import resource, sys, numpy as np
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, WaypointPath, build_problem, plan
robot, path = robots.load("ur5"), WaypointPath(np.array({waypoints}))
limits = LimitRequest(kinds={constraints!r}, overrides={{"jerk": [40.0] * 6}})
plan(build_problem(robot, path, METHODS[{method!r}], limits=limits, grid=100))
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
plan(build_problem(robot, path, METHODS[{method!r}], limits=limits, grid={grid}))
print((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base) / 1024)
"""
#: The methods whose memory per grid interval and joint the runner's admission uses
#: (``bytes_per_interval_joint``), with the grids they are measured on.
MEMORY_GRIDS = {"min_cost": [1000, 2000, 4000], "jerk_limited": [1000, 2000], "toppra": [10_000], "phase_plane": [10_000]}


def min_cost_memory(grids: list[int]) -> None:
    print("\nur5 (4 waypoints): peak RSS growth of one solve, in a fresh process, and per interval and joint")
    print(f"{'method':>13s} {'grid_points':>11s} {'+MB':>8s} {'B/int.joint':>11s} {'s':>7s}")
    for method, method_grids in MEMORY_GRIDS.items():
        constraints = ["velocity", "acceleration", "torque"] + (["jerk"] if method == "jerk_limited" else [])
        for grid in method_grids if method != "min_cost" else grids:
            started = time.monotonic()
            out = subprocess.run(
                [sys.executable, "-c", _PEAK.format(waypoints=UR5, grid=grid, method=method, constraints=constraints)],
                cwd=ROOT, capture_output=True, text=True, check=True,
            )
            grown = float(out.stdout.split()[-1])
            print(f"{method:>13s} {grid:11d} {grown:8.0f} {grown * 2**20 / (grid * 6):11.0f} {time.monotonic() - started:7.1f}")
    server = Server(TOPTRAJ_PRELOAD_ROBOTS="false")
    try:
        server.request("GET", "/v1/robots/ur5")
        server.wait_until_idle()
        before = server.rss_mb()
        body = _slow_requests()["min_cost, grid 4000"]
        statuses = [server.request("POST", "/v1/trajectories", body)[0] for _ in range(3)]
        after = server.rss_mb()
        print(
            f"RSS of the server process / the processes under it: {before[0]:.0f} / {before[1]:.0f} MB before, "
            f"{after[0]:.0f} / {after[1]:.0f} MB after three min_cost requests at grid 4000 {statuses}"
        )
    finally:
        server.close()


def health_during_large_body() -> None:
    server = Server(TOPTRAJ_PRELOAD_ROBOTS="false")
    try:
        server.request("GET", "/v1/robots/ur5")
        request = {"robot": "ur5", "path": {"waypoints": UR5}, "timing": {"method": "phase_plane"}, "output": {"dt": 1e-5}}
        status, content = server.request("POST", "/v1/trajectories", request)
        found = re.search(r"output\.dt >= ([0-9.e+-]+) s", content.decode(errors="replace")[:2000])
        smallest = float(found.group(1)) if found else None
        print(f"\n/health while the largest body is produced (output.dt = 1e-05 s gets {status}; smallest dt that fits: {smallest} s)")
        for dt in filter(None, (1e-5, smallest)):
            answer = {}
            thread = threading.Thread(
                target=lambda dt=dt, answer=answer: answer.update(
                    started=time.monotonic(),
                    response=server.request("POST", "/v1/trajectories", {**request, "output": {"dt": dt}}),
                    ended=time.monotonic(),
                )
            )
            thread.start()
            latencies = []
            while True:
                started = time.monotonic()
                server.request("GET", "/health")
                latencies.append(time.monotonic() - started)
                if not thread.is_alive():
                    break
                time.sleep(0.02)
            thread.join()
            status, content = answer["response"]
            print(
                f"  dt = {dt:g} s: {status}, {len(content) / 1e6:.1f} MB in {answer['ended'] - answer['started']:.2f} s; "
                f"/health x{len(latencies)}: median {1e3 * np.median(latencies):.1f} ms, max {1e3 * max(latencies):.1f} ms"
            )
    finally:
        server.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--skip", default="", help="comma-separated parts to skip: idle, memory, health")
    parser.add_argument("--budget", type=float, default=1.5)
    args = parser.parse_args()
    skip = set(filter(None, args.skip.split(",")))
    if "idle" not in skip:
        idle_after_504(args.budget)
    if "memory" not in skip:
        min_cost_memory([1000, 2000, 4000])
    if "health" not in skip:
        health_during_large_body()
    return 0


if __name__ == "__main__":
    sys.exit(main())
