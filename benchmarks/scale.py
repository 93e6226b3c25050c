"""How the typical request scales with the number of waypoints: time and peak memory.

For 2, 10, 100 and 1,000 ur5 waypoints (a seeded random walk of 0.3 rad steps inside the joint
range; spline, velocity + acceleration + torque, ``phase_plane``, samples every 10 ms), each in
a fresh process so that its peak RSS is its own: the planning time (``plan_request``, best of
``--repeat``), the time to build and encode the JSON body, the body's size, the grid, and the
peak RSS above the process's RSS after imports and a warm-up request. Prints the time per
waypoint and per second of motion, to show whether cost grows linearly.

    python benchmarks/scale.py [--sizes 2 10 100 1000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def waypoints(count: int, seed: int = 3) -> list[list[float]]:
    """A random walk of ``count`` ur5 waypoints, 0.3 rad per step per joint at most, kept well
    inside the joint range."""
    import numpy as np

    rng = np.random.default_rng(seed)
    point = np.array([0.0, -1.2, 1.0, 0.0, 0.0, 0.0])
    rows = [point.copy()]
    while len(rows) < count:
        point = np.clip(point + rng.uniform(-0.3, 0.3, 6), -2.5, 2.5)
        point[2] = np.clip(point[2], -2.5, 2.5)
        rows.append(point.copy())
    return [row.tolist() for row in rows]


def _measure(count: int, repeat: int) -> dict:
    """In this process: plan the request of ``count`` waypoints and measure it."""
    sys.path.insert(0, str(ROOT))
    import numpy as np

    from toptraj.service.planning import encode_json, plan_request, trajectory_body
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    def request(rows):
        return TrajectoryRequest.model_validate({
            "robot": "ur5",
            "path": {"kind": "waypoints", "waypoints": rows, "interpolation": "spline"},
            "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
            "output": {"dt": 0.01},
        })

    from toptraj.planners.paths import SplinePath
    from toptraj.planners.paths.grid import path_grid

    encode_json(trajectory_body(plan_request(request(waypoints(4)))))  # imports, numba cache
    baseline = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    body = request(waypoints(count))
    plan_s, encode_s = [], []
    for _ in range(repeat):
        started = time.perf_counter()
        result = plan_request(body)
        planned = time.perf_counter()
        encoded = encode_json(trajectory_body(result))
        plan_s.append(planned - started)
        encode_s.append(time.perf_counter() - planned)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {
        "waypoints": count,
        "duration_s": result.duration,
        "grid_points": int(len(path_grid(SplinePath(np.array(waypoints(count)))))),
        "samples": int(len(result.samples.t)),
        "plan_s": min(plan_s),
        "encode_s": min(encode_s),
        "body_bytes": len(encoded),
        "peak_rss_above_warm_mb": (peak - baseline) / 1024.0,
        "peak_rss_mb": peak / 1024.0,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[2, 10, 100, 1000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one is not None:
        print(json.dumps(_measure(args.one, args.repeat)))
        return 0
    print(f"{'waypoints':>9s} {'motion s':>9s} {'grid':>6s} {'samples':>8s} {'plan ms':>9s} {'encode ms':>10s} "
          f"{'body MB':>8s} {'peak RSS MB':>12s} {'(+ over warm)':>13s} {'plan ms/wp':>11s} {'plan ms/motion s':>17s}")
    for count in args.sizes:
        output = subprocess.run(
            [sys.executable, __file__, "--one", str(count), "--repeat", str(args.repeat)],
            capture_output=True, text=True, check=True, cwd=ROOT,
        ).stdout
        row = json.loads(output.strip().splitlines()[-1])
        print(
            f"{row['waypoints']:9d} {row['duration_s']:9.3f} {row['grid_points']:6d} {row['samples']:8d} "
            f"{1e3 * row['plan_s']:9.1f} {1e3 * row['encode_s']:10.1f} {row['body_bytes'] / 1e6:8.2f} "
            f"{row['peak_rss_mb']:12.0f} {row['peak_rss_above_warm_mb']:13.1f} "
            f"{1e3 * row['plan_s'] / row['waypoints']:11.2f} {1e3 * row['plan_s'] / row['duration_s']:17.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
