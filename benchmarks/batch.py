"""Batches on Ray: requests/s of ``toptraj batch`` with 1 and with 2 Ray workers, results
identical to planning the requests one by one, and a resumed run that plans nothing.

The requests: ``--count`` seeded ur5 and panda spline paths (3 waypoints within 80 % of the
joint ranges, velocity + acceleration + torque, phase_plane), half each. Each run starts its own
local Ray (its start-up is timed apart from the planning) and plans the whole file into a fresh
output; the rate is requests over the planning time. A sample of ``--check`` results is
compared with the service's own answer planned in this process.

    python benchmarks/batch.py [--count 2000] [--check 50]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import orjson

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from toptraj import robots  # noqa: E402
from toptraj.service.batches import run_batch  # noqa: E402
from toptraj.service.planning import plan_request, render  # noqa: E402
from toptraj.service.schemas.trajectories import TrajectoryRequest  # noqa: E402


def requests(count: int, seed: int = 2026) -> list[str]:
    rng = np.random.default_rng(seed)
    lines = []
    for k in range(count):
        robot = ("ur5", "panda")[k % 2]
        limits = robots.load(robot).limits
        low, high = np.maximum(limits.position_lower, -2.5), np.minimum(limits.position_upper, 2.5)
        waypoints = rng.uniform(low, high, (3, len(low))) * 0.8
        lines.append(json.dumps({"robot": robot, "path": {"waypoints": waypoints.tolist()}}))
    return lines


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=2000)
    parser.add_argument("--check", type=int, default=50)
    args = parser.parse_args()
    import ray

    work = Path(tempfile.mkdtemp(prefix="toptraj-batch-bench-"))
    source = work / "requests.jsonl"
    lines = requests(args.count)
    source.write_text("\n".join(lines) + "\n")
    rates = {}
    for workers in (1, 2):
        output = work / f"results-{workers}.jsonl"
        started = time.perf_counter()
        ray.init(num_cpus=workers, include_dashboard=False, object_store_memory=100 * 1024 * 1024, log_to_driver=False, configure_logging=False)
        up = time.perf_counter() - started
        report = run_batch(source, output, workers)
        again = run_batch(source, output, workers)
        ray.shutdown()
        rows = [json.loads(row) for row in output.read_text().splitlines()]
        statuses = {}
        for row in rows:
            statuses[row["status"]] = statuses.get(row["status"], 0) + 1
        rates[workers] = report.rate
        print(f"{workers} Ray worker(s): Ray up in {up:.1f} s; {report.planned} requests in {report.seconds:.1f} s = "
              f"{report.rate:.1f} requests/s; statuses {statuses}; resumed run planned {again.planned}")
    print(f"ratio 2 workers / 1 worker: {rates[2] / rates[1]:.2f}")
    rows = {json.loads(row)["line"]: json.loads(row) for row in (work / "results-2.jsonl").read_text().splitlines()}
    same = 0
    for number in np.linspace(1, args.count, min(args.check, args.count)).astype(int):
        request = TrajectoryRequest.model_validate_json(lines[number - 1])
        try:
            alone = orjson.loads(render(plan_request(request), request)[0])
        except Exception as error:  # an impossible request: the batch line must carry the error
            same += rows[number]["status"] != 200 and type(error).__name__ != ""
            continue
        row = rows[number]["body"]
        same += row["duration"] == alone["duration"] and row["samples"]["q"] == alone["samples"]["q"]
    print(f"identical to planning one by one: {same} of {min(args.check, args.count)} checked")


if __name__ == "__main__":
    main()
