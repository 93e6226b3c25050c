"""Jobs, measured on a real server over loopback (one job worker).

1. Overhead: the typical ur5 request answered synchronously and as a job (submitted, polled
   every 10 ms until done), interleaved; medians and their ratio. The job pays for its worker
   process (a fork of the fork server) and for loading the compiled kernels there.
2. The synchronous endpoint while a job computes: the typical request's latency with the job
   worker idle and with a free-path collocation running, interleaved; medians and ratio.
3. Cancelling: a running collocation job is deleted; printed are the time from the DELETE's
   answer until its worker process is gone, and the CPU-s the server's process tree used in the
   second after.

    python benchmarks/jobs.py [--rounds 10]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time

import psutil

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from tests.live_server import LiveServer  # noqa: E402

UR5 = [
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
]
TYPICAL = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5}}
COLLOCATION = {
    "robot": "ur5",
    "path": {"kind": "free", "start": [0.0] * 6, "goal": [0.5] * 6},
    "timing": {"method": "collocation", "grid_points": 60},
}


def _json(server: LiveServer, method: str, path: str, body: dict | None = None) -> tuple[int, dict]:
    status, _, content = server.request(method, path, body)
    return status, json.loads(content)


def _job_until(server: LiveServer, job_id: str, statuses: set[str], every_s: float = 0.01) -> dict:
    while (job := _json(server, "GET", f"/v1/jobs/{job_id}")[1])["status"] not in statuses:
        time.sleep(every_s)
    return job


def _synchronous_s(server: LiveServer) -> float:
    started = time.perf_counter()
    assert _json(server, "POST", "/v1/trajectories", TYPICAL)[0] == 200
    return time.perf_counter() - started


def _as_job_s(server: LiveServer) -> float:
    started = time.perf_counter()
    job = _json(server, "POST", "/v1/jobs", {"trajectory": TYPICAL})[1]
    assert _job_until(server, job["id"], {"done", "failed"})["status"] == "done"
    return time.perf_counter() - started


def _workers(server: LiveServer) -> list[psutil.Process]:
    root = psutil.Process(server.process.pid)
    forkservers = [child for child in root.children() if "forkserver" in " ".join(child.cmdline())]
    return [worker for forkserver in forkservers for worker in forkserver.children()]


def _gone(process: psutil.Process) -> bool:
    try:
        return not process.is_running() or process.status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as data_dir, LiveServer(
        TOPTRAJ_DATA_DIR=data_dir, TOPTRAJ_JOB_WORKERS="1", TOPTRAJ_PRELOAD_ROBOTS="true"
    ) as server:
        _synchronous_s(server), _as_job_s(server)  # first uses
        server.wait_until_idle()

        synchronous, as_job = [], []
        for _ in range(args.rounds):
            synchronous.append(_synchronous_s(server))
            as_job.append(_as_job_s(server))
        s, j = statistics.median(synchronous), statistics.median(as_job)
        print(f"1. typical ur5 request: synchronous {s * 1e3:.0f} ms, as a job {j * 1e3:.0f} ms (median of "
              f"{args.rounds}); job / synchronous = {j / s:.2f}")

        idle, busy = [], []
        job = _json(server, "POST", "/v1/jobs", {"trajectory": COLLOCATION})[1]
        _job_until(server, job["id"], {"running"})
        for _ in range(args.rounds):
            busy.append(_synchronous_s(server))
        _json(server, "DELETE", f"/v1/jobs/{job['id']}")
        server.wait_until_idle()
        for _ in range(args.rounds):
            idle.append(_synchronous_s(server))
        i, b = statistics.median(idle), statistics.median(busy)
        print(f"2. synchronous latency: job worker idle {i * 1e3:.0f} ms, computing a collocation {b * 1e3:.0f} ms "
              f"(median of {args.rounds}); ratio {b / i:.2f} (2 cores: the job takes one)")

        for round_ in range(3):
            server.wait_until_idle()
            job = _json(server, "POST", "/v1/jobs", {"trajectory": COLLOCATION})[1]
            _job_until(server, job["id"], {"running"})
            time.sleep(1.0)
            workers = _workers(server)
            status, answer = _json(server, "DELETE", f"/v1/jobs/{job['id']}")
            answered = time.perf_counter()
            while not all(map(_gone, workers)):
                time.sleep(0.001)
            gone_ms = (time.perf_counter() - answered) * 1e3
            before = server.cpu_seconds()
            time.sleep(1.0)
            cpu = server.cpu_seconds() - before
            print(f"3. cancel {round_ + 1}: DELETE answered {status} ({answer['status']}), worker gone "
                  f"{gone_ms:.0f} ms after the answer, then {cpu:.3f} CPU-s in 1 s")


if __name__ == "__main__":
    main()
