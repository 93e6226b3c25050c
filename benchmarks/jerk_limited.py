"""``jerk_limited`` against ``phase_plane`` (the jerk-free optimum) on seeded random paths, in
one interleaved run.

For each of ``--paths`` seeded random spline paths (half ur5, half panda; 2 to 5 waypoints,
within the joint ranges), with velocity, acceleration and torque limits (the torque scaled down
until holding the arm still along the path takes 1 / 1.3 of it somewhere, so that it shapes the
motion), and jerk limits for ``jerk_limited``: both methods time the path through ``toptraj.planners.plan`` (the library call the
service makes, limit gate included), alternately, ``--repeats`` times each; the median solve
time of each is kept. Every answer's limits are recomputed from 1 ms samples (velocity and
acceleration as returned, torque by RNEA, jerk by finite differences of the accelerations).
Prints, per robot and overall: the duration ratio jerk_limited / phase_plane (>= 1: the price of
the jerk limit), the solve-time ratio, the worst recomputed utilization of each limit, and the
paths that failed.

    python benchmarks/jerk_limited.py [--paths 50] [--repeats 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.problem.waypoints import make_path

JERK_FREE = ("velocity", "acceleration", "torque")
JERK = (*JERK_FREE, "jerk")


def _random_waypoints(robot, rng) -> np.ndarray:
    lower = np.maximum(robot.limits.position_lower, -3.0)
    upper = np.minimum(robot.limits.position_upper, 3.0)
    margin = 0.15 * (upper - lower)
    return rng.uniform(lower + margin, upper - margin, (int(rng.integers(2, 6)), robot.dof))


def _torque_scale(robot, waypoints) -> float:
    """The torque scale at which holding still along the path takes 1 / 1.3 of the limit."""
    q = make_path(robot, WaypointPath(waypoints))(np.linspace(0.0, 1.0, 400))
    gravity = np.abs(robot.inverse_dynamics(q, np.zeros_like(q), np.zeros_like(q))) / robot.limits.torque
    return min(1.0, 1.3 * float(gravity.max()))


def _utilization(robot, samples, scales) -> dict[str, float]:
    """Worst |value| / limit over the samples, per kind."""
    limits = robot.limits.with_request(scales=scales)
    jerk = np.diff(samples.qdd, axis=0) / np.diff(samples.t)[:, None]
    torque = robot.inverse_dynamics(samples.q, samples.qd, samples.qdd)
    values = {"velocity": samples.qd, "acceleration": samples.qdd, "torque": torque, "jerk": jerk}
    return {kind: float(np.max(np.abs(value) / getattr(limits, kind))) for kind, value in values.items()}


def _timed(robot, waypoints, method, kinds, scales):
    started = time.perf_counter()
    result = plan(build_problem(robot, WaypointPath(waypoints), METHODS[method], limits=LimitRequest(kinds=kinds, scales=scales), sampling=Sampling(dt=1e-3)))
    return time.perf_counter() - started, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paths", type=int, default=50)
    parser.add_argument("--repeats", type=int, default=3)
    arguments = parser.parse_args()
    arms = {name: robots.load(name) for name in ("ur5", "panda")}
    rows, failures = [], []
    for index in range(arguments.paths):
        name = ("ur5", "panda")[index % 2]
        robot = arms[name]
        waypoints = _random_waypoints(robot, np.random.default_rng(1000 + index))
        times = {"phase_plane": [], "jerk_limited": []}
        results = {}
        try:
            scales = {"torque": _torque_scale(robot, waypoints)}
            for _ in range(arguments.repeats):
                for method, kinds in (("phase_plane", JERK_FREE), ("jerk_limited", JERK)):
                    seconds, results[method] = _timed(robot, waypoints, method, kinds, scales)
                    times[method].append(seconds)
        except (InfeasiblePath, TimingFailed) as error:
            failures.append((name, index, f"{type(error).__name__}: {error.detail[:120]}"))
            continue
        jerk_limited, jerk_free = results["jerk_limited"], results["phase_plane"]
        rows.append({
            "robot": name,
            "index": index,
            "duration_ratio": jerk_limited.duration / jerk_free.duration,
            "time_ratio": float(np.median(times["jerk_limited"]) / np.median(times["phase_plane"])),
            "solve_ms": 1e3 * float(np.median(times["jerk_limited"])),
            "utilization": _utilization(robot, jerk_limited.samples, scales),
            "reported_jerk": float(jerk_limited.peak_utilization["jerk"].max()),
        })
        print(
            f"{name:6s} #{index:2d}  duration x{rows[-1]['duration_ratio']:.4f}  solve {rows[-1]['solve_ms']:7.1f} ms "
            f"(x{rows[-1]['time_ratio']:.2f} phase_plane)  worst utilization "
            + " ".join(f"{kind} {value:.4f}" for kind, value in rows[-1]["utilization"].items())
        )
    print()
    for label, group in (("ur5", "ur5"), ("panda", "panda"), ("all", None)):
        chosen = [row for row in rows if group is None or row["robot"] == group]
        if not chosen:
            continue
        ratios = np.array([row["duration_ratio"] for row in chosen])
        speed = np.array([row["time_ratio"] for row in chosen])
        solve = np.array([row["solve_ms"] for row in chosen])
        worst = {kind: max(row["utilization"][kind] for row in chosen) for kind in chosen[0]["utilization"]}
        print(
            f"{label:6s} {len(chosen):2d} paths: duration jerk_limited / phase_plane median {np.median(ratios):.4f} "
            f"(min {ratios.min():.4f}, max {ratios.max():.4f}); solve time median {np.median(solve):.0f} ms, "
            f"x{np.median(speed):.1f} phase_plane (p95 x{np.percentile(speed, 95):.1f}); worst recomputed utilization "
            + ", ".join(f"{kind} {value:.4f}" for kind, value in worst.items())
        )
    print(f"failed: {len(failures)}")
    for failure in failures:
        print("  ", *failure)


if __name__ == "__main__":
    main()
