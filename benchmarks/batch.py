"""Batches: the throughput of ``toptraj batch`` on a local Ray against the single-request rate
measured in the same run, and against ``POST /v1/batches``; results identical to planning the
requests one by one; a resumed run that plans nothing.

The requests: ``--count`` mixed lines, seeded ur5 and panda spline paths (3 waypoints within
80 % of the joint ranges, velocity + acceleration + torque) timed in turn by ``phase_plane``,
``toppra``, ``min_cost``, ``quintic`` and a compare of ``phase_plane`` and ``toppra``. Each
round, interleaved:

* single: the lines one after another over HTTP to a ``toptraj serve`` (one process, warm);
  the single-request rate is lines over that time;
* POST /v1/batches: the same lines as one job on that server, timed until the job is done;
* toptraj batch: ``run_batch`` on a local Ray of ``--workers`` CPUs (default: the cores),
  three times: "whole", the command as a user runs it (Ray started and shut down by it);
  "cold", on a Ray started apart (its workers started and prepared during the run); "warm",
  again on those workers (the rate of a long batch, once its workers are ready).

Printed: each rate, and the ratios the goals name: toptraj batch / (cores x single) (goal
>= 0.8) and toptraj batch / POST /v1/batches (goal >= 1).

    python benchmarks/batch.py [--count 50] [--rounds 2] [--check 10]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.live_server import LiveServer  # noqa: E402
from toptraj import robots  # noqa: E402
from toptraj.service.batches import run_batch  # noqa: E402
from toptraj.service.batches.prepare import SETUP_HOOK  # noqa: E402

#: The timing of each line in turn (a list: a compare of these methods).
TIMINGS: list[str | list[str]] = ["phase_plane", "toppra", "min_cost", "quintic", ["phase_plane", "toppra"]]
#: Lines per ``POST /v1/batches`` job (200 mixed lines answer more than a job keeps).
JOB_LINES = 50


def requests(count: int, seed: int = 2026) -> list[dict]:
    rng = np.random.default_rng(seed)
    bodies = []
    for k in range(count):
        robot = ("ur5", "panda")[k % 2]
        limits = robots.load(robot).limits
        low, high = np.maximum(limits.position_lower, -2.5), np.minimum(limits.position_upper, 2.5)
        waypoints = rng.uniform(low, high, (3, len(low))) * 0.8
        body: dict = {"robot": robot, "path": {"waypoints": waypoints.tolist()}}
        timing = TIMINGS[k % len(TIMINGS)]
        if isinstance(timing, list):
            body["methods"] = timing
        else:
            body["timing"] = {"method": timing}
        bodies.append(body)
    return bodies


def single(server: LiveServer, bodies: list[dict]) -> tuple[float, list[tuple[int, dict]]]:
    """Seconds to answer ``bodies`` one after another over HTTP, and the answers."""
    answers = []
    started = time.perf_counter()
    for body in bodies:
        path = "/v1/trajectories/compare" if "methods" in body else "/v1/trajectories"
        status, _, content = server.request("POST", path, body)
        answers.append((status, json.loads(content)))
    return time.perf_counter() - started, answers


def as_job(server: LiveServer, bodies: list[dict]) -> float:
    """Seconds for ``POST /v1/batches`` of ``bodies`` to be done: jobs of ``JOB_LINES`` lines
    (a job's answer is capped in size), submitted at once."""
    started = time.perf_counter()
    ids = []
    for k in range(0, len(bodies), JOB_LINES):
        status, _, content = server.request("POST", "/v1/batches", {"requests": bodies[k : k + JOB_LINES]})
        assert status == 202, content
        ids.append(json.loads(content)["id"])
    for job_id in ids:
        while (job := json.loads(server.request("GET", f"/v1/jobs/{job_id}")[2]))["status"] not in ("done", "failed"):
            time.sleep(0.02)
        assert job["status"] == "done", job
    return time.perf_counter() - started


def on_ray(source: Path, work: Path, workers: int, tag: str) -> dict[str, float]:
    """Seconds of ``toptraj batch`` whole, cold and warm (module docstring); the result files
    are ``work/<tag>-<kind>.jsonl``."""
    import ray

    seconds = {}
    started = time.perf_counter()
    run_batch(source, work / f"{tag}-whole.jsonl", workers)
    seconds["whole"] = time.perf_counter() - started
    ray.init(num_cpus=workers, include_dashboard=False, object_store_memory=100 * 1024 * 1024, log_to_driver=False,
             configure_logging=False, runtime_env={"worker_process_setup_hook": SETUP_HOOK})
    try:
        for kind in ("cold", "warm"):
            report = run_batch(source, work / f"{tag}-{kind}.jsonl", workers)
            seconds[kind] = report.seconds
        assert run_batch(source, work / f"{tag}-warm.jsonl", workers).planned == 0  # resumed: nothing left
    finally:
        ray.shutdown()
    return seconds


def same_answers(rows_path: Path, answers: list[tuple[int, dict]], check: int) -> int:
    """How many of ``check`` lines spread over the file carry the status and duration (or
    durations of a compare) the single requests answered."""
    rows = {row["line"]: row for row in map(json.loads, rows_path.read_text().splitlines())}
    same = 0
    for number in np.linspace(1, len(answers), min(check, len(answers))).astype(int):
        status, alone = answers[number - 1]
        row = rows[number]
        if "results" in alone:
            same += row["status"] == status and [r.get("duration") for r in row["body"]["results"]] == [r.get("duration") for r in alone["results"]]
        else:
            same += row["status"] == status and row["body"].get("duration") == alone.get("duration")
    return same


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=50)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--check", type=int, default=10)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="toptraj-batch-bench-"))
    bodies = requests(args.count)
    source = work / "requests.jsonl"
    source.write_text("\n".join(json.dumps(body) for body in bodies) + "\n")
    cores = args.workers
    print(f"{args.count} mixed lines ({', '.join(map(str, TIMINGS))} in turn), {cores} Ray workers, {os.cpu_count()} cores")
    with LiveServer(TOPTRAJ_JOB_WORKERS="1") as server:
        server.wait_until_idle()
        single(server, bodies[: len(TIMINGS)])  # each method's first run (its imports) not timed
        for round_ in range(1, args.rounds + 1):
            single_s, answers = single(server, bodies)
            job_s = as_job(server, bodies)
            ray_s = on_ray(source, work, cores, f"round{round_}")
            rate = {"single": args.count / single_s, "POST /v1/batches": args.count / job_s}
            rate.update({f"toptraj batch ({kind})": args.count / s for kind, s in ray_s.items()})
            print(f"round {round_}: " + "; ".join(f"{name} {value:.2f} lines/s" for name, value in rate.items()))
            for kind in ray_s:
                ours = rate[f"toptraj batch ({kind})"]
                print(f"  toptraj batch ({kind}): {ours / (cores * rate['single']):.2f} x cores x single (goal >= 0.8), "
                      f"{ours / rate['POST /v1/batches']:.2f} x POST /v1/batches (goal >= 1)")
            for kind in ray_s:
                counts = Counter(json.loads(row)["status"] for row in (work / f"round{round_}-{kind}.jsonl").read_text().splitlines())
                print(f"  toptraj batch ({kind}) statuses: {dict(sorted(counts.items()))}; single: {dict(sorted(Counter(s for s, _ in answers).items()))}")
            same = same_answers(work / f"round{round_}-warm.jsonl", answers, args.check)
            print(f"  identical to the single requests: {same} of {min(args.check, args.count)} checked")


if __name__ == "__main__":
    main()
