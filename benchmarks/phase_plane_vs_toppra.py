"""Time of ``phase_plane`` against TOPP-RA at equal accuracy, in one interleaved run.

Seeded random spline paths (2 to 5 waypoints within the middle 70 % of each joint's range, the
spline inside the joint limits) on ur5, panda, geering_2r and yamamoto_2r, under velocity,
acceleration and torque limits (each robot's limits as loaded; the two-link arms have torque
limits only). For each path:

* the converged duration T* is the Richardson extrapolation 2 T(20,000) - T(10,000) of the
  conservative (interpolation) discretization on 20,000 and 10,000 intervals, checked against
  the midpoint (second-order) discretization on 20,000 intervals: the two must agree within
  1e-5, else the path is reported and left out;
* for each method, the smallest grid of LADDER (``path_grid(path, n)``, n intervals) whose
  duration lies within 0.1 % of T* is found, and the method is timed there, best of
  ``--repeats``, the methods interleaved in each repetition.

What each time includes (the path object itself, ``SplinePath`` or toppra's
``SplineInterpolator``, is built beforehand for every method):

* ``pp``: ``phase_plane`` as a user of toptraj pays for it: the constraint build
  (``build_path_constraints``: path derivatives and a batched Pinocchio RNEA at each grid point)
  plus ``PhasePlaneMethod().solve`` (which evaluates the constraints anew at the points its grid
  refinement adds). ``pp solve``: the solve alone, on constraints built beforehand.
* ``adapter``: the ``toppra`` method of toptraj: the same constraint build plus
  ``ToppraMethod().solve`` (toppra's Seidel solver on the precomputed rows).
* ``toppra``: toppra used directly through its public API, as a user of toppra pays for it:
  ``JointVelocityConstraint``, ``JointAccelerationConstraint``, ``JointTorqueConstraint``
  (toppra's default discretizations: interpolation for acceleration, collocation for torque)
  with an inverse-dynamics callback ``pin.rnea(model, data, q, v, a) + damping * v``,
  ``TOPPRA(..., solver_wrapper="seidel")`` (which evaluates the constraints) and
  ``compute_parameterization(0, 0)``.
* ``drake`` (ur5 only, when ``pydrake`` imports: ``pip install toptraj[bench]``): Drake's
  ``Toppra`` on a ``MultibodyPlant`` parsed from the same URDF (visual and collision elements
  stripped), the same spline as a ``PiecewisePolynomial.CubicHermite``, ``AddJointVelocityLimit``,
  ``AddJointAccelerationLimit``, ``AddJointTorqueLimit`` and ``SolvePathParameterization``; the
  plant is built beforehand.

Ratios are the other method's time over ``pp`` (> 1: phase_plane is faster). Prints one line per
path, then the median, p5 and min of each ratio, per robot and overall, and every path where
phase_plane is slower.

    python benchmarks/phase_plane_vs_toppra.py [--paths 16] [--repeats 5] [--robots ur5,panda,...]
"""

from __future__ import annotations

import argparse
import logging
import re
import sys
import time
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

import robots
from planners.constraints import build_path_constraints
from planners.errors import InfeasiblePath, TimingFailed
from planners.grid import path_grid
from planners.paths import SplinePath
from planners.timing import PhasePlaneMethod, ToppraMethod
from planners.timing.phase_plane import midpoint_duration

LADDER = (25, 50, 75, 100, 150, 200, 300, 450, 600, 900, 1200, 1800, 2400, 3600, 5000, 7200, 10000)
KINDS = ("velocity", "acceleration", "torque")
ROBOTS = ("ur5", "panda", "geering_2r", "yamamoto_2r")
ACCURACY = 1e-3
#: Largest disagreement of the two estimates of the converged duration.
CONVERGED = 1e-5

logging.getLogger("toppra").setLevel(logging.ERROR)
logging.getLogger("drake").setLevel(logging.CRITICAL)


def random_path(robot, rng) -> tuple[np.ndarray, SplinePath]:
    """2 to 5 waypoints within the middle 70 % of each joint's range (+-pi for continuous joints),
    drawn until the spline through them stays within the joint limits."""
    lower = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    upper = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    middle, half = 0.5 * (lower + upper), 0.35 * (upper - lower)
    while True:
        waypoints = middle + rng.uniform(-1, 1, (int(rng.integers(2, 6)), robot.dof)) * half
        path = SplinePath(waypoints)
        q = path(np.linspace(0.0, 1.0, 1000))
        if np.all(q >= robot.limits.position_lower) and np.all(q <= robot.limits.position_upper):
            return waypoints, path


def converged_duration(path, robot) -> tuple[float, float]:
    """T* (Richardson, see the module docstring) and its relative gap to the midpoint estimate."""
    unrefined = PhasePlaneMethod(max_refinements=0)
    fine = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, 20_000))
    coarse = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, 10_000))
    richardson = 2.0 * unrefined.solve(fine).duration - unrefined.solve(coarse).duration
    return richardson, abs(midpoint_duration(fine) / richardson - 1.0)


@dataclass
class Timed:
    """One method's equal-accuracy grid and its times (best of the repetitions), in s."""

    grid: int
    duration: float
    total: float = np.inf
    solve: float = np.inf
    detail: str = ""


def toptraj_runner(method, path, robot):
    """(total, solve, duration, detail) of a toptraj method at n intervals."""

    def run(n):
        started = time.perf_counter()
        constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, n))
        built = time.perf_counter()
        result = method.solve(constraints)
        done = time.perf_counter()
        return done - started, done - built, result.duration, f"{len(result.s) - 1}"

    return run


def toppra_runner(robot, waypoints, path):
    """(total, nan, duration, "") of toppra through its public API at n intervals. Limits that
    are infinite (the two-link arms have only torque limits) are left out, as a toppra user would."""
    import toppra
    import toppra.algorithm
    import toppra.constraint

    model = robot.model
    data = model.createData()
    damping = robot.viscous_friction
    to_configuration = robot.configuration if np.any(robot.continuous) else (lambda q: q)

    def inverse_dynamics(q, v, a):
        return pin.rnea(model, data, to_configuration(q), v, a) + damping * v

    spline = toppra.SplineInterpolator(path.knots, waypoints, bc_type="natural")
    limits = robot.limits

    def constraints():
        made = []
        if np.all(np.isfinite(limits.velocity)):
            made.append(toppra.constraint.JointVelocityConstraint(np.column_stack([-limits.velocity, limits.velocity])))
        if np.all(np.isfinite(limits.acceleration)):
            made.append(
                toppra.constraint.JointAccelerationConstraint(np.column_stack([-limits.acceleration, limits.acceleration]))
            )
        made.append(
            toppra.constraint.JointTorqueConstraint(
                inverse_dynamics, np.column_stack([-limits.torque, limits.torque]), robot.coulomb_friction
            )
        )
        return made

    def run(n):
        grid = path_grid(path, n)
        started = time.perf_counter()
        instance = toppra.algorithm.TOPPRA(constraints(), spline, gridpoints=grid, solver_wrapper="seidel")
        _, sd, _ = instance.compute_parameterization(0.0, 0.0)
        done = time.perf_counter()
        if sd is None:
            raise TimingFailed("toppra found no parameterization")
        return done - started, np.nan, float(np.sum(2.0 * np.diff(grid) / (sd[1:] + sd[:-1]))), ""

    return run


def drake_plant(robot):
    """Drake's MultibodyPlant of ``robot``'s URDF without visual and collision elements (their
    meshes are package:// URIs), or ``None`` when pydrake is absent."""
    try:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant
    except ImportError:
        return None
    from robots.catalog import EXAMPLE_ARMS, example_urdf_path

    with open(example_urdf_path(EXAMPLE_ARMS[robot.name].loader)) as handle:
        text = re.sub(r"<(visual|collision)\b.*?</\1>", "", handle.read(), flags=re.S)
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(text, "urdf")
    if 'name="world"' not in text:
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(plant.GetBodyByName(robot.model.names[1]).name()))
    plant.Finalize()
    names = tuple(plant.get_joint(index).name() for index in plant.GetJointIndices() if plant.get_joint(index).num_positions() == 1)
    if names[: robot.dof] != robot.joint_names:
        raise RuntimeError(f"Drake's joint order {names} differs from Pinocchio's {robot.joint_names}")
    return plant


def drake_runner(plant, robot, waypoints, path, failures: list):
    """(total, nan, duration, "") of Drake's Toppra at n intervals; grids where it fails are
    appended to ``failures``."""
    from pydrake.multibody.optimization import Toppra
    from pydrake.trajectories import PiecewisePolynomial

    # Cubic Hermite through the knots with the spline's own slopes: the same cubic per segment.
    spline = PiecewisePolynomial.CubicHermite(path.knots, waypoints.T, path.evaluate(path.knots).dq.T)
    limits = robot.limits

    def run(n):
        grid = path_grid(path, n)
        started = time.perf_counter()
        toppra = Toppra(spline, plant, grid)
        toppra.AddJointVelocityLimit(-limits.velocity, limits.velocity)
        toppra.AddJointAccelerationLimit(-limits.acceleration, limits.acceleration)
        toppra.AddJointTorqueLimit(-limits.torque, limits.torque)
        result = toppra.SolvePathParameterization()
        done = time.perf_counter()
        if result is None:
            failures.append(n)
            raise TimingFailed("Drake's Toppra failed")
        return done - started, np.nan, float(result.end_time()), ""

    return run


def equal_accuracy(run, reference) -> Timed | None:
    """The smallest ladder grid whose duration is within ACCURACY of ``reference``."""
    for n in LADDER:
        try:
            _, _, duration, _ = run(n)
        except (InfeasiblePath, TimingFailed):
            continue
        if abs(duration / reference - 1.0) <= ACCURACY:
            return Timed(n, duration)
    return None


def time_interleaved(runs: dict, found: dict, repeats: int) -> None:
    """Best-of-``repeats`` times of every method at its grid, the methods interleaved."""
    for _ in range(repeats):
        for name, run in runs.items():
            timed = found[name]
            total, solve, _, detail = run(timed.grid)
            timed.total = min(timed.total, total)
            timed.solve = min(timed.solve, solve) if np.isfinite(solve) else timed.solve
            timed.detail = detail


def summary(label: str, values) -> str:
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return f"{label}: no paths"
    return (
        f"{label}: median {np.median(values):6.2f}  p5 {np.percentile(values, 5):6.2f}  "
        f"min {values.min():6.2f}  ({values.size} paths)"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paths", type=int, default=16, help="paths per robot")
    parser.add_argument("--repeats", type=int, default=5, help="timed repetitions per method (best of)")
    parser.add_argument("--robots", default=",".join(ROBOTS))
    parser.add_argument("--seed", type=int, default=2024)
    args = parser.parse_args()

    warm = robots.load("ur5")
    warm_waypoints, warm_path = random_path(warm, np.random.default_rng(0))
    for run in (
        toptraj_runner(PhasePlaneMethod(), warm_path, warm),
        toptraj_runner(ToppraMethod(), warm_path, warm),
        toppra_runner(warm, warm_waypoints, warm_path),
    ):
        run(50)

    rows = {"toppra": [], "adapter": [], "adapter solve": [], "drake": []}
    per_robot: dict[str, dict[str, list]] = {}
    slower, missed, unconverged, drake_failures = [], [], [], {}
    drake_available = True
    print(
        f"{'robot':11s} {'path':>4s} {'T* s':>8s} | {'pp N':>5s} {'->':>5s} {'ms':>6s} {'solve':>6s} | "
        f"{'tp N':>5s} {'ms':>7s} | {'ad N':>5s} {'ms':>7s} {'solve':>7s} | {'drake N':>7s} {'ms':>7s} | "
        f"{'toppra/pp':>9s} {'adapter/pp':>10s} {'solve/solve':>11s} {'drake/pp':>8s}"
    )
    for name in args.robots.split(","):
        robot = robots.load(name)
        plant = drake_plant(robot) if name == "ur5" else None
        if name == "ur5" and plant is None:
            drake_available = False
        rng = np.random.default_rng(args.seed + ROBOTS.index(name) if name in ROBOTS else args.seed)
        ratios = per_robot.setdefault(name, {"toppra": [], "adapter": []})
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
                "pp": toptraj_runner(PhasePlaneMethod(), path, robot),
                "toppra": toppra_runner(robot, waypoints, path),
                "adapter": toptraj_runner(ToppraMethod(), path, robot),
            }
            if plant is not None:
                failures = drake_failures.setdefault(done, [])
                runs["drake"] = drake_runner(plant, robot, waypoints, path, failures)
            found = {method: equal_accuracy(run, reference) for method, run in runs.items()}
            if any(found[method] is None for method in ("pp", "toppra", "adapter")):
                missed.append((name, done, {method: timed and timed.grid for method, timed in found.items()}))
                done += 1
                continue
            drake = found.get("drake")
            if drake is None:
                runs.pop("drake", None)
                found.pop("drake", None)
            time_interleaved(runs, found, args.repeats)
            pp, tp, ad = found["pp"], found["toppra"], found["adapter"]
            ratio_toppra, ratio_adapter, ratio_solve = tp.total / pp.total, ad.total / pp.total, ad.solve / pp.solve
            rows["toppra"].append(ratio_toppra)
            rows["adapter"].append(ratio_adapter)
            rows["adapter solve"].append(ratio_solve)
            ratios["toppra"].append(ratio_toppra)
            ratios["adapter"].append(ratio_adapter)
            drake_text = f"{'-':>7s} {'-':>7s}"
            ratio_drake = ""
            if drake is not None:
                rows["drake"].append(drake.total / pp.total)
                drake_text = f"{drake.grid:7d} {1e3 * drake.total:7.2f}"
                ratio_drake = f"{drake.total / pp.total:8.2f}"
            elif plant is not None:
                drake_text = f"{'missed':>7s} {'':>7s}"
            print(
                f"{name:11s} {done:4d} {reference:8.4f} | {pp.grid:5d} {pp.detail:>5s} {1e3 * pp.total:6.2f} {1e3 * pp.solve:6.2f} | "
                f"{tp.grid:5d} {1e3 * tp.total:7.2f} | {ad.grid:5d} {1e3 * ad.total:7.2f} {1e3 * ad.solve:7.2f} | {drake_text} | "
                f"{ratio_toppra:9.2f} {ratio_adapter:10.2f} {ratio_solve:11.2f} {ratio_drake:>8s}",
                flush=True,
            )
            if min(ratio_toppra, ratio_adapter) < 1.0:
                slower.append((name, done, pp, tp, ad))
            done += 1

    print()
    print("Times at equal accuracy (each method on the smallest ladder grid within 0.1 % of T*), best of", args.repeats)
    print("pp = build_path_constraints + PhasePlaneMethod().solve; toppra = toppra's public API incl. its own")
    print("constraint evaluation; adapter = build_path_constraints + ToppraMethod().solve; solve/solve = the two")
    print("solves alone on prebuilt constraints (phase_plane's includes the rows it evaluates while refining).")
    for robot_name, ratios in per_robot.items():
        print(summary(f"{robot_name:11s} toppra / pp ", ratios["toppra"]))
        print(summary(f"{robot_name:11s} adapter / pp", ratios["adapter"]))
    print(summary("all         toppra / pp          ", rows["toppra"]))
    print(summary("all         adapter / pp         ", rows["adapter"]))
    print(summary("all         adapter solve / pp solve", rows["adapter solve"]))
    if drake_available and "ur5" in args.robots.split(","):
        print(summary("ur5         drake / pp           ", rows["drake"]))
        failed = {index: grids for index, grids in drake_failures.items() if grids}
        if failed:
            print(
                "Drake's Toppra failed ('failed to find the maximum path acceleration') on "
                + "; ".join(f"ur5 path {index} at {', '.join(map(str, grids))} intervals" for index, grids in failed.items())
            )
    elif "ur5" in args.robots.split(","):
        print("drake: pydrake not installed (pip install toptraj[bench]); skipped")
    for name, index, gap in unconverged:
        print(f"not converged: {name} path {index}: the two estimates of T* differ by {gap:.1e}; left out")
    for name, index, grids in missed:
        print(f"missed: {name} path {index}: a method missed 0.1 % on every ladder grid: {grids}")
    if slower:
        for name, index, pp, tp, ad in slower:
            print(
                f"slower: {name} path {index}: phase_plane N={pp.grid} {1e3 * pp.total:.2f} ms, "
                f"toppra N={tp.grid} {1e3 * tp.total:.2f} ms, adapter N={ad.grid} {1e3 * ad.total:.2f} ms"
            )
    else:
        print("phase_plane is slower on no path (against toppra directly or through the adapter)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
