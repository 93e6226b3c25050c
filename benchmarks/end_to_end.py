"""The typical request end to end against its anchors, interleaved in one run.

The typical request: ur5, 4 spline waypoints, velocity + acceleration + torque, ``phase_plane``,
samples every 10 ms. Each round times, in a shuffled order:

* **bare toppra**: one solve of the same path and limits through toppra's own public API, as a
  toppra user writes it: ``SplineInterpolator`` on the service's spline (chord-length knots,
  natural ends: ``anchors.typical_spline``), ``JointVelocityConstraint``,
  ``JointAccelerationConstraint`` and ``JointTorqueConstraint`` with a ``pin.rnea`` callback,
  ``TOPPRA`` on 100 evenly spaced grid intervals (the service chooses its own grid),
  ``compute_trajectory`` (its constraint evaluation, both passes and the parameterization);
* **drake** (when ``pydrake`` imports: ``pip install toptraj[bench]``): Drake's ``Toppra`` on
  the same cubic (a ``PiecewisePolynomial.CubicHermite`` with toppra's spline's values and
  slopes at its knots), the same limits and 100 grid intervals, on a ``MultibodyPlant`` of the
  same URDF built beforehand: ``Toppra(...)``, the three ``Add...Limit`` calls and
  ``SolvePathParameterization``;
* **RNEA floor**: 3 RNEA per grid point of the grid our answer was actually timed on (the
  build grid and the points the phase-plane refinement added), in one batched call of
  Pinocchio's ``rneaInParallel`` on one thread (an anchor outside our code: ``Robot.rnea``
  takes toptraj's own compiled pass);
* **library**: ``toptraj.planners.plan`` for the request (no HTTP, no JSON);
* **planning thread**: what a server's planning thread does: the request's schema object to
  JSON bytes (``plan_request``, ``trajectory_body``, ``encode_json``);
* **HTTP**: ``POST /v1/trajectories`` to ``toptraj serve --workers 1`` over one keep-alive
  loopback connection, the body read in full;
* **HTTP again**: the same request once more right after each HTTP probe (not a probe of its
  own in the shuffle, so that no HTTP probe follows it): the server answers it without having
  been idle, as a server under steady load does.

Prints the medians and the ratios of the goals (HTTP <= 1.0x bare toppra and <= 8x the RNEA
floor; library <= 0.6x bare toppra) and, with Drake, the same against Drake's Toppra, then (``--profile``) the stages of a request as shares
of its HTTP median: the planning thread's median split by ``cProfile``'s shares of its work, the
HTTP stack the rest (split into what the server spends when it comes to the request without
having been idle, HTTP again - planning thread, and the rest, HTTP - HTTP again: waking from
idle). The medians come from the interleaved rounds, where each probe finds the caches as the
others left them (the same work timed in a loop of its own is about 1.5 ms faster).

    python benchmarks/end_to_end.py [--rounds 300] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import http.client
import json
import os
import pstats
import random
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from anchors import bare_toppra, drake_solver  # noqa: E402

from toptraj import robots  # noqa: E402
from toptraj.service.planning import encode_json, plan_request, trajectory_body  # noqa: E402
from toptraj.service.schemas.trajectories import TrajectoryRequest  # noqa: E402

WAYPOINTS = [
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
]
TYPICAL = {
    "robot": "ur5",
    "path": {"kind": "waypoints", "waypoints": WAYPOINTS, "interpolation": "spline"},
    "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
    "output": {"dt": 0.01},
}
#: Stages of the profile: a label and the functions whose cumulative time it is (the first
#: that appears in the profile counts; nested stages are subtracted from their parents).
STAGES = (
    ("request to library arguments", ("plan_request",), ("plan",)),
    ("path construction and checks", ("make_path", "check_path_within_limits"), ()),
    ("constraint build (grid rows)", ("build_path_constraints",), ()),
    ("timing solve (incl. refinement)", ("solve_well_scaled",), ()),
    ("dense limit check (the gate)", ("check_limits",), ()),
    ("sampling at dt", ("sample_trajectory",), ()),
    ("dense check of the samples", ("samples_exceed",), ()),
    ("conditioning", ("conditioning_along",), ()),
    ("phase-plane picture", ("_phase_plane",), ()),
    ("response body", ("trajectory_body",), ()),
    ("JSON encoding", ("encode_json",), ()),
)


def timing_grid_points(problem) -> tuple[int, int]:
    """(points of the grids the answer was timed on, points of the grids its constraints were
    first built on), over its stretches: what ``toptraj.planners.plan`` times, without the sampling."""
    from toptraj.planners.runner.run import _given_path

    timed, _, _ = _given_path(problem, problem.deadline)
    return sum(len(item.timing.s) for item in timed.stretches), sum(len(item.constraints.s) for item in timed.stretches)


def rnea_floor(pool: pin.ModelPool, states: list[np.ndarray]) -> None:
    """3 RNEA per grid point, batched: ``states`` holds q, qd and qdd, each (n_dof, 3 * points),
    Fortran-ordered as Pinocchio's ``rneaInParallel`` takes them."""
    pin.rneaInParallel(1, pool, states[0], states[1], states[2])


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _serve(port: int) -> subprocess.Popen:
    server = subprocess.Popen(
        [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(port), "--workers", "1"],
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    give_up = time.monotonic() + 120
    while time.monotonic() < give_up:
        try:
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=2)
            connection.request("GET", "/health")
            if connection.getresponse().status == 200:
                return server
        except OSError:
            time.sleep(0.2)
    server.kill()
    raise RuntimeError("the server did not come up")


def _timed(function) -> float:
    started = time.perf_counter()
    function()
    return time.perf_counter() - started


def _profile(request: TrajectoryRequest, http_median_s: float, again_median_s: float, thread_median_s: float, calls: int = 100) -> None:
    """Stage shares of the HTTP median: the planning thread's median (interleaved with the other
    probes, as the HTTP median is) split by cProfile's shares of its work, and the HTTP stack as
    the difference of the two medians."""

    def thread_work():
        return encode_json(trajectory_body(plan_request(request)))

    profiler = cProfile.Profile()
    profiler.enable()
    for _ in range(calls):
        thread_work()
    profiler.disable()
    stats = pstats.Stats(profiler).stats
    cumulative: dict[str, float] = {}
    for (_, _, name), (_, _, _, total, _) in stats.items():
        cumulative[name] = cumulative.get(name, 0.0) + total
    profiled = cumulative.get("thread_work", 0.0)
    unprofiled = thread_median_s
    scale = unprofiled / (profiled / calls)  # cProfile's own overhead taken out, evenly
    rows, accounted = [], 0.0
    for label, names, nested in STAGES:
        seconds = sum(cumulative.get(name, 0.0) for name in names) - sum(cumulative.get(name, 0.0) for name in nested)
        seconds = scale * seconds / calls
        accounted += seconds
        rows.append((label, seconds))
    rows.append(("rest of the planning thread", unprofiled - accounted))
    rows.append(("HTTP stack, server busy (HTTP again - thread)", again_median_s - unprofiled))
    rows.append(("server waking from idle (HTTP - HTTP again)", http_median_s - again_median_s))
    print(f"\nstages of the typical request (shares of the HTTP median {1e3 * http_median_s:.2f} ms; cProfile, "
          f"its overhead scaled out):")
    for label, seconds in sorted(rows, key=lambda row: -row[1]):
        print(f"  {label:46s} {1e3 * seconds:7.3f} ms  {100 * seconds / http_median_s:5.1f} %")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=300)
    parser.add_argument("--profile", action="store_true", help="print the stages of a request")
    args = parser.parse_args()

    import toppra

    toppra.setup_logging("WARNING")
    robot = robots.load("ur5")
    waypoints = np.array(WAYPOINTS)
    request = TrajectoryRequest.model_validate(TYPICAL)
    payload = json.dumps(TYPICAL).encode()
    from toptraj.planners import plan
    from toptraj.planners.execution.deadline import NO_DEADLINE
    from toptraj.planners.execution.memory import MAX_SAMPLES
    from toptraj.planners.generators.search.graph import DEFAULT_SEARCH_MEMORY
    from toptraj.service.mapping import problem_of

    problem = problem_of(request, robot, NO_DEADLINE, MAX_SAMPLES, False, DEFAULT_SEARCH_MEMORY)
    answer = plan(problem)
    grid_points, built_points = timing_grid_points(problem)
    rng = np.random.default_rng(0)
    states = [np.asfortranarray(rng.uniform(-1.0, 1.0, (robot.dof, 3 * grid_points))) for _ in range(3)]
    pool = pin.ModelPool(robot.model, 1)

    port = _free_port()
    server = _serve(port)
    try:
        connection = http.client.HTTPConnection("127.0.0.1", port, timeout=60)

        def http_call():
            connection.request("POST", "/v1/trajectories", payload, {"content-type": "application/json"})
            response = connection.getresponse()
            body = response.read()
            if response.status != 200:
                raise RuntimeError(f"HTTP {response.status}: {body[:300]!r}")

        drake = drake_solver(robot, waypoints)
        probes = {
            "bare toppra": lambda: bare_toppra(robot, waypoints),
            **({"drake": drake} if drake is not None else {}),
            "RNEA floor": lambda: rnea_floor(pool, states),
            "library": lambda: plan(problem_of(request, robot, NO_DEADLINE, MAX_SAMPLES, False, DEFAULT_SEARCH_MEMORY)),
            "planning thread": lambda: encode_json(trajectory_body(plan_request(request))),
            "HTTP": http_call,
        }
        for function in probes.values():  # warm-up
            for _ in range(5):
                function()
        times: dict[str, list[float]] = {name: [] for name in (*probes, "HTTP again")}
        order = list(probes)
        shuffle = random.Random(1)
        for _ in range(args.rounds):
            shuffle.shuffle(order)
            for name in order:
                times[name].append(_timed(probes[name]))
                if name == "HTTP":
                    times["HTTP again"].append(_timed(http_call))
        median = {name: float(np.median(values)) for name, values in times.items()}
        print(f"typical request: ur5, 4 spline waypoints, velocity + acceleration + torque, dt 0.01; "
              f"{args.rounds} interleaved rounds; duration {answer.duration:.4f} s (bare toppra "
              f"{bare_toppra(robot, waypoints):.4f} s at 100 intervals"
              f"{f', drake {drake():.4f} s' if drake is not None else ''}); timed on {grid_points} grid points "
              f"({built_points} built, the rest added by the refinement)")
        for name, values in times.items():
            print(f"  {name:16s} p50 {1e3 * median[name]:8.3f} ms   p95 {1e3 * np.percentile(values, 95):8.3f} ms")
        goals = (
            ("HTTP p50 / bare toppra", median["HTTP"] / median["bare toppra"], 1.0),
            ("HTTP p50 / RNEA floor", median["HTTP"] / median["RNEA floor"], 8.0),
            ("library / bare toppra", median["library"] / median["bare toppra"], 0.6),
        )
        print()
        for label, ratio, goal in goals:
            print(f"  {label:24s} {ratio:7.2f}x   goal <= {goal:g}x   {'met' if ratio <= goal else 'MISSED'}")
        print(f"  {'HTTP again / bare toppra':24s} {median['HTTP again'] / median['bare toppra']:7.2f}x   (the server without its idle gap)")
        if drake is None:
            print("  drake: pydrake not installed (pip install toptraj[bench]); skipped")
        else:
            for name in ("HTTP", "library"):
                print(f"  {name + ' p50 / drake':24s} {median[name] / median['drake']:7.2f}x")
        if args.profile:
            _profile(request, median["HTTP"], median["HTTP again"], median["planning thread"])
    finally:
        server.terminate()
        server.wait(timeout=10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
