"""Time of ``phase_plane`` against TOPP-RA at equal accuracy, in one interleaved run.

Seeded random spline paths (2 to 5 waypoints within the middle 70 % of each joint's range, the
spline inside the joint limits) on ur5, panda, geering_2r and yamamoto_2r, under velocity,
acceleration and torque limits (each robot's limits as loaded; the two-link arms have torque
limits only). For each path:

* the converged duration T* (``converged.py``) is the Richardson extrapolation 2 T(2N) - T(N) of the
  conservative (interpolation) discretization, N = 10,000 intervals and every interval then
  halved, checked against the midpoint (second-order) discretization on the 2N intervals: the
  two must agree within 1e-5 (else the same on 20,000 and 40,000 intervals; else the path is
  reported and left out);
* for each method, the smallest grid of LADDER (``path_grid(path, n)``, n intervals) whose
  duration lies within 0.1 % of T* is found, and so is the smallest from which the method
  stays within 0.1 % on the next two ladder grids as well (a method whose error changes sign
  as the grid grows can land within 0.1 % on one coarse grid by chance); each method is timed
  on those grids, best of ``--repeats``, the methods interleaved in each repetition.

What each time includes (the path object itself, ``SplinePath`` or toppra's
``SplineInterpolator``, is built beforehand for every method):

* ``pp``: ``phase_plane`` as a user of toptraj pays for it: the constraint build
  (``build_path_constraints``: path derivatives and the batched RNEA of ``Robot.rnea_sets`` at each
  grid point)
  plus ``PhasePlaneMethod(excursion=None).solve`` (which evaluates the constraints anew at the
  points its grid refinement adds; the share of the time spent evaluating rows is printed too).
  ``solve``: the solve alone, on constraints built beforehand. Its refinement aims at the
  duration alone, as the other methods' grids do: none of them holds the limits between grid
  points (``--excursion``: with phase_plane's default refinement of the limits' excursions
  between grid points too, which a coarse grid pays for with points).
* ``adapter``: the ``toppra`` method of toptraj: the same constraint build plus
  ``ToppraMethod().solve`` (toppra's Seidel solver on the precomputed rows).
* ``toppra``: toppra used directly through its public API (``anchors.py``), as a user of toppra
  pays for it:
  ``SplineInterpolator`` through the same waypoints and knots (natural ends: the same spline),
  ``JointVelocityConstraint``, ``JointAccelerationConstraint``, ``JointTorqueConstraint`` (toppra's
  default discretizations: interpolation for acceleration, collocation for torque, which holds
  the torque rows only at the start of each interval and typically comes out below T*) with an
  inverse-dynamics callback ``pin.rnea(model, data, q, v, a) + damping * v``,
  ``TOPPRA(..., solver_wrapper="seidel")`` (which evaluates the constraints) and
  ``compute_parameterization(0, 0)``. ``toppra-i``: the same with the interpolation
  discretization for torque as well, conservative like phase_plane's.
* ``drake`` (ur5 only, when ``pydrake`` imports: ``pip install toptraj[bench]``): Drake's
  ``Toppra`` on a ``MultibodyPlant`` parsed from the same URDF (visual and collision elements
  stripped), the same spline as a ``PiecewisePolynomial.CubicHermite``, ``AddJointVelocityLimit``,
  ``AddJointAccelerationLimit``, ``AddJointTorqueLimit`` and ``SolvePathParameterization``; the
  plant is built beforehand. Drake also runs (untimed) on 2,400 and 4,096 intervals of each
  path, and the grids where it fails are reported.

Ratios are the other method's time over ``pp`` (> 1: phase_plane is faster), also with
phase_plane given the other method's grid. Prints one line per path, then the median, p5 and min
of each ratio, per robot and overall, and every path where phase_plane is slower.

Times are the CPU time of the process (``time.process_time``) by default: every method runs in
this one thread (toptraj's compiled RNEA, Pinocchio's RNEA in toppra's callbacks, toppra's
Cython solver, Drake), and on
a shared machine a run's wall time also holds the waits for other processes, which grow with
the run's length. ``--clock wall`` times with ``time.perf_counter`` instead.

    python benchmarks/phase_plane_vs_toppra.py [--paths 16] [--repeats 7] [--robots ur5,panda,...] [--clock cpu]
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from anchors import drake_plant, drake_runner, toppra_runner
from converged import CONVERGED, KINDS, converged_duration, random_path

from toptraj import robots
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing import PhasePlaneMethod, ToppraMethod

LADDER = (25, 50, 75, 100, 150, 200, 300, 450, 600, 900, 1200, 1800, 2400, 3600, 5000, 7200, 10000)
ROBOTS = ("ur5", "panda", "geering_2r", "yamamoto_2r")
ACCURACY = 1e-3
#: Fine grids on which Drake's Toppra is also run (untimed), to report where it fails.
DRAKE_FINE = (2400, 4096)

#: The clock the runs are timed with (``--clock``): the process's CPU time by default.
CLOCKS = {"cpu": time.process_time, "wall": time.perf_counter}
_clock = [CLOCKS["cpu"]]


def _now() -> float:
    return _clock[0]()


logging.getLogger("toppra").setLevel(logging.ERROR)
logging.getLogger("drake").setLevel(logging.CRITICAL)


def toptraj_runner(method, path, robot):
    """A run of a toptraj method at n intervals: (total, solve, duration, detail, evaluation),
    times in s; detail: the number of intervals it ended on; evaluation: the time spent
    evaluating constraint rows (the build, and the rows at the points refinement adds)."""

    def run(n):
        spent = [0.0]

        def timed(evaluate):
            # Refined constraints keep the evaluate of the ones they refine (with_points).
            def evaluate_timed(extra_s):
                started = _now()
                try:
                    return evaluate(extra_s)
                finally:
                    spent[0] += _now() - started

            return evaluate_timed

        started = _now()
        constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, n))
        built = _now()
        constraints = dataclasses.replace(constraints, evaluate=timed(constraints.evaluate))
        replaced = _now()
        result = method.solve(constraints)
        done = _now()
        spent[0] += built - started
        return done - started - (replaced - built), done - replaced, result.duration, f"{len(result.s) - 1}", spent[0]

    return run


@dataclass
class Scan:
    """A method's durations on the ladder and its two equal-accuracy grids: the smallest grid
    within ACCURACY of T* (``first``), and the smallest from which the method stays within it
    on the next two ladder grids as well (``settled``); ``None`` where there is none."""

    durations: dict = field(default_factory=dict)
    first: int | None = None
    settled: int | None = None


def scan(run, reference) -> Scan:
    """Run the method up the ladder until its settled grid is found (or the ladder ends)."""
    result = Scan()
    within = []
    for n in LADDER:
        try:
            duration = run(n)[2]
        except (InfeasiblePath, TimingFailed):
            duration = np.nan
        result.durations[n] = duration
        within.append(bool(abs(duration / reference - 1.0) <= ACCURACY))
        if within[-1] and result.first is None:
            result.first = n
        if len(within) >= 3 and all(within[-3:]):
            result.settled = LADDER[len(within) - 3]
            return result
    return result


def time_interleaved(runs: dict, wanted: dict, repeats: int) -> dict:
    """Best-of-``repeats`` [total, solve, detail, evaluation, duration] of every method at each
    of its grids in ``wanted`` (method -> set of grids), the methods interleaved in each
    repetition; solve and evaluation from the repetition with the best total."""
    best = {(method, n): [np.inf, np.inf, "", np.nan, np.nan] for method, grids in wanted.items() for n in grids}
    for _ in range(repeats):
        for (method, n), record in best.items():
            total, solve, duration, detail, evaluation = runs[method](n)
            if total < record[0]:
                record[0], record[2], record[3], record[4] = total, detail, evaluation, duration
            record[1] = min(record[1], solve) if np.isfinite(solve) else record[1]
    return best


def summary(label: str, values) -> str:
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return f"{label}: no paths"
    return (
        f"{label}: median {np.median(values):6.2f}  p5 {np.percentile(values, 5):6.2f}  "
        f"min {values.min():6.2f}  ({values.size} paths)"
    )


OTHERS = ("toppra", "toppra-i", "adapter", "drake")
#: How the two grids of a comparison are chosen: each method's smallest ladder grid within 0.1 %
#: (the primary comparison), each one's settled grid, or phase_plane on the other's grid.
DEFINITIONS = {
    "first": "each method at the smallest ladder grid within 0.1 % of T*",
    "settled": "each method at the smallest ladder grid from which it stays within 0.1 % on the next two",
    "same": "phase_plane given the other method's grid (the smallest within 0.1 % for the other)",
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paths", type=int, default=16, help="paths per robot")
    parser.add_argument("--repeats", type=int, default=7, help="timed repetitions per method (best of)")
    parser.add_argument("--robots", default=",".join(ROBOTS))
    parser.add_argument("--seed", type=int, default=2024)
    parser.add_argument(
        "--clock", choices=sorted(CLOCKS), default="cpu",
        help="cpu: the process's CPU time (time.process_time; a run's time does not grow with the waits "
        "for other processes on a shared machine); wall: time.perf_counter",
    )
    parser.add_argument(
        "--excursion", action="store_true",
        help="phase_plane with its default refinement of the limits' excursions between grid points",
    )
    args = parser.parse_args()
    names = args.robots.split(",")
    _clock[0] = CLOCKS[args.clock]
    phase_plane = PhasePlaneMethod() if args.excursion else PhasePlaneMethod(excursion=None)

    warm = robots.load("ur5")
    warm_waypoints, warm_path = random_path(warm, np.random.default_rng(0))
    for run in (
        toptraj_runner(phase_plane, warm_path, warm),
        toptraj_runner(ToppraMethod(), warm_path, warm),
        toppra_runner(warm, warm_waypoints, warm_path, _now),
    ):
        run(50)

    # ratios[definition][robot][method]: the other method's time / phase_plane's time
    ratios = {definition: {} for definition in DEFINITIONS}
    evaluation_share, slower, missed, unconverged, drake_failures, off = [], [], [], [], {}, []
    drake_available = None
    print(
        f"{'robot':11s} {'path':>4s} {'T* s':>7s} | {'pp N':>4s} {'pts':>5s} {'ms':>6s} {'solve':>5s} {'eval':>4s} | "
        f"{'tp N':>4s} {'ms':>6s} | {'tpi N':>5s} {'ms':>7s} | {'ad N':>4s} {'ms':>6s} {'solve':>6s} | "
        f"{'dk N':>4s} {'ms':>6s} | ratio toppra toppra-i adapter solve drake | settled: toppra adapter | same grid: toppra adapter"
    )
    for name in names:
        robot = robots.load(name)
        plant = drake_plant(robot) if name == "ur5" else None
        if name == "ur5":
            drake_available = plant is not None
        rng = np.random.default_rng(args.seed + (ROBOTS.index(name) if name in ROBOTS else 0))
        for definition in DEFINITIONS:
            ratios[definition][name] = {method: [] for method in (*OTHERS, "adapter solve")}
        done = 0
        while done < args.paths:
            waypoints, path = random_path(robot, rng)
            try:
                reference, gap = converged_duration(path, robot)
            except (InfeasiblePath, TimingFailed):
                continue  # no timing can follow this path within the limits: draw another
            if gap > CONVERGED:
                unconverged.append((name, done, gap))
                done += 1
                continue
            runs = {
                "pp": toptraj_runner(phase_plane, path, robot),
                "toppra": toppra_runner(robot, waypoints, path, _now),
                "toppra-i": toppra_runner(robot, waypoints, path, _now, interpolation=True),
                "adapter": toptraj_runner(ToppraMethod(), path, robot),
            }
            if plant is not None:
                failures = drake_failures.setdefault(done, [])
                runs["drake"] = drake_runner(plant, robot, waypoints, path, _now, failures)
            scans = {method: scan(run, reference) for method, run in runs.items()}
            if "drake" in runs:
                for n in DRAKE_FINE:  # not timed: does it solve on fine grids at all?
                    try:
                        runs["drake"](n)
                    except TimingFailed:
                        pass
            if any(scans[method].first is None for method in ("pp", "toppra", "toppra-i", "adapter")):
                missed.append((name, done, {method: (found.first, found.settled) for method, found in scans.items()}))
                done += 1
                continue
            wanted = {method: {grid for grid in (found.first, found.settled) if grid is not None} for method, found in scans.items()}
            wanted["pp"] |= {found.first for method, found in scans.items() if method != "pp" and found.first is not None}
            times = time_interleaved(runs, wanted, args.repeats)

            def at(method, grid):
                """(grid, total, solve, detail, evaluation, duration) of ``method`` at ``grid``."""
                return None if grid is None else (grid, *times[(method, grid)])

            rows = {}
            for definition in DEFINITIONS:
                row = rows[definition] = {}
                for method in OTHERS:
                    if method not in scans:
                        continue
                    other = at(method, getattr(scans[method], "first" if definition == "same" else definition))
                    pp = at("pp", other[0] if definition == "same" and other else getattr(scans["pp"], "first" if definition == "same" else definition))
                    if pp is None or other is None:
                        continue
                    if definition == "same" and abs(pp[5] / reference - 1.0) > ACCURACY:
                        off.append((name, done, other[0], pp[5] / reference - 1.0))
                        continue
                    row[method] = other[1] / pp[1]
                    ratios[definition][name][method].append(row[method])
                    if method == "adapter":
                        row["adapter solve"] = other[2] / pp[2]
                        ratios[definition][name]["adapter solve"].append(row["adapter solve"])
            if min(rows["first"].get("toppra", np.inf), rows["first"].get("adapter", np.inf)) < 1.0:
                slower.append((name, done, {method: at(method, scans[method].first) for method in scans}))

            pp = at("pp", scans["pp"].first)
            adapter = at("adapter", scans["adapter"].first)
            evaluation_share.append(pp[4] / pp[1])

            def cell(method, width):
                found = at(method, scans[method].first) if method in scans else None
                if found is None:
                    return f"{'-':>{width}s} {'-':>6s}"
                return f"{found[0]:{width}d} {1e3 * found[1]:6.2f}"

            def number(row, method, width):
                return f"{row[method]:{width}.2f}" if method in row else f"{'-':>{width}s}"

            print(
                f"{name:11s} {done:4d} {reference:7.4f} | {pp[0]:4d} {pp[3]:>5s} {1e3 * pp[1]:6.2f} {1e3 * pp[2]:5.2f} "
                f"{100 * pp[4] / pp[1]:3.0f}% | {cell('toppra', 4)} | {cell('toppra-i', 5)} | "
                f"{adapter[0]:4d} {1e3 * adapter[1]:6.2f} {1e3 * adapter[2]:6.2f} | {cell('drake', 4)} | "
                f"{number(rows['first'], 'toppra', 12)} {number(rows['first'], 'toppra-i', 8)} "
                f"{number(rows['first'], 'adapter', 7)} {number(rows['first'], 'adapter solve', 5)} "
                f"{number(rows['first'], 'drake', 5)} | {number(rows['settled'], 'toppra', 14)} "
                f"{number(rows['settled'], 'adapter', 7)} | {number(rows['same'], 'toppra', 16)} {number(rows['same'], 'adapter', 7)}",
                flush=True,
            )
            done += 1

    clock = "CPU time of the process" if args.clock == "cpu" else "wall time"
    print()
    print(f"Times: {clock}, best of {args.repeats}, the methods interleaved. Ratio = the other method's time /")
    print("phase_plane's (> 1: phase_plane is faster). pp = build_path_constraints + PhasePlaneMethod().solve,")
    print(f"its refinement {'with' if args.excursion else 'without'} the limits' excursions between grid points")
    print("(eval: its share spent evaluating constraint rows, the build and the rows at refinement points);")
    print("toppra = toppra's public API with its default discretizations (collocation for torque), its own")
    print("constraint evaluation included; toppra-i = the same with the interpolation discretization for torque")
    print("too (conservative, as phase_plane); adapter = build_path_constraints + ToppraMethod().solve;")
    print("adapter solve = the two solves alone on prebuilt constraints (phase_plane's includes the rows it")
    print("evaluates while refining); drake = Drake's Toppra (ur5).")
    for definition, described in DEFINITIONS.items():
        print(f"{described}:")
        if definition == "first":
            for robot_name, robot_ratios in ratios[definition].items():
                for method in ("toppra", "toppra-i", "adapter"):
                    print(summary(f"  {robot_name:11s} {method:13s} / pp", robot_ratios[method]))
        for method in (*OTHERS, "adapter solve"):
            if method == "drake" and not drake_available:
                continue
            pooled = [value for robot_ratios in ratios[definition].values() for value in robot_ratios[method]]
            label = "ur5 drake" if method == "drake" else f"all {method}"
            print(summary(f"  {label:25s} / pp", pooled))
    share = np.array(evaluation_share)
    print(
        f"phase_plane's time spent evaluating constraint rows: median {100 * np.median(share):.0f} %, "
        f"p5 {100 * np.percentile(share, 5):.0f} %, p95 {100 * np.percentile(share, 95):.0f} %"
    )
    if drake_available is False:
        print("drake: pydrake not installed (pip install toptraj[bench]); skipped")
    failed = {index: grids for index, grids in drake_failures.items() if grids}
    if drake_available:
        print(
            f"Drake's Toppra (also run on {' and '.join(map(str, DRAKE_FINE))} intervals, untimed) failed "
            f"(\"failed to find the maximum path acceleration\") on {len(failed)} of {len(drake_failures)} ur5 paths"
            + (": " + "; ".join(f"path {index} at {', '.join(map(str, grids))}" for index, grids in failed.items()) if failed else "")
        )
    for name, index, gap in unconverged:
        print(f"not converged: {name} path {index}: the two estimates of T* differ by {gap:.1e}; left out")
    for name, index, grids in missed:
        print(f"missed: {name} path {index}: a method missed 0.1 % on every ladder grid (first, settled): {grids}")
    for name, index, grid, error in off:
        print(f"off: {name} path {index}: phase_plane given {grid} intervals is {error:+.2e} off T*; left out of 'same grid'")
    if slower:
        for name, index, found in slower:
            described = ", ".join(
                f"{method} N={value[0]} {1e3 * value[1]:.2f} ms" for method, value in found.items() if value is not None
            )
            print(f"slower: {name} path {index}: {described}")
    else:
        print("phase_plane is slower than toppra (directly or through the adapter) on no path")
    return 0


if __name__ == "__main__":
    sys.exit(main())
