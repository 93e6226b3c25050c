"""Local optimization of a path among obstacles (Jeong & Lee §2.6, after Shiller & Dubowsky
1991): a seed path from start to goal becomes a clamped cubic B-spline
(``toptraj.planners.paths.bspline``) whose interior control points minimize

    J(P) = T(P) + W_obstacle * v_obstacle(P) + W_range * v_range(P)

with T the path-constrained time-optimal duration along the spline, at rest at both ends
(``toptraj.planners.timing.phase_plane.method``, reused unchanged), and penalty functions on the obstacle
distance and the joint ranges; the number of control points grows, round by round, until the
duration stops improving.

How it is made fast enough. T costs one constraint evaluation (RNEA at every grid point) and
one phase-plane integration; it dominates everything else, so:

* While optimizing, T is the midpoint-discretization duration (``midpoint_duration``: second
  order, no refinement) on a fixed uniform grid of ``LocalSettings.grid_intervals`` intervals
  (512: about 0.2 ms on a 2-joint arm; on 256 the optimizer finds paths whose midpoint duration
  is 5 % below their exact one, and the Geering arm's free motion stays at its seed, 1.0152 s
  instead of 0.9773 s). At the end of each round the path is timed exactly: the default
  phase-plane method with its grid refinement (relative tolerance 6e-4), on the default grid,
  which is what the round reports and the answer returns.
* The optimizer is derivative-free: Nelder-Mead (SciPy, adaptive coefficients) over the
  interior control points; a round ends when its simplex has converged (within 1e-4 rad of
  its best point, its objectives within 1e-6 s) or its evaluations run out. Rounds often
  spend hundreds of evaluations without progress before a large gain (the Geering arm's free
  motion: 0.1 % in the first 514 of 600 evaluations at 5 control points, then 3 %), so looser
  tolerances or fewer evaluations end them too early. T along a path is continuous but only
  piecewise smooth in the path's shape (the switching structure changes), and the exact
  penalty below has kinks, so finite-difference gradients would be unreliable (on the Geering
  example, on a 256-interval grid, L-BFGS-B on them stops at 1.072 s and Powell's method at
  0.988 s after 16,296 evaluations, where Nelder-Mead reaches 0.983 s after 12,285); Nelder-
  Mead needs no gradient and never returns a point worse than its start.
* Each evaluation is one compiled call (``local_objective.Objective``,
  ``objective_kernels``): the spline's coefficients from basis weights computed once per
  round, then the same kernels as the reference path (constraint rows, phase-plane sweeps,
  distances) without building its objects, so J is the same to rounding and Nelder-Mead walks
  the same simplices (the Geering example: the same 12,501 evaluations and rounds, 0.98279 s),
  at 0.18 ms an evaluation instead of 0.5 ms on the Geering arm, 1.9 instead of 2.8 ms on ur5
  and 3.4 instead of 7.2 ms on panda (a shared 2-core machine; on the six- and seven-joint
  arms the box distances of the penalty and the sweeps over their rows are the larger part).
  Nelder-Mead itself runs compiled around that call (``simplex``, ``simplex_kernels``: SciPy's
  loop step for step, the same simplices and evaluations), which saves SciPy's Python work per
  evaluation, about a tenth of the round on the two-joint arm.
* Rounds are nested. The knots are inserted dyadically (1/2; 1/4, 3/4; 1/8, 7/8; 3/8, 5/8;
  ...), giving 4, 5, 7, 9, 11, ... control points, and each round starts from the previous
  optimum exactly (Boehm's knot insertion leaves the curve unchanged). The optimization grid
  holds every dyadic knot, so it is the same grid in every round, and the objective of the
  best point of each round is never above that of the round before.
* Rounds end when the exact duration has improved by less than ``improvement`` in ``patience``
  successive rounds, or at once when a round finds nothing faster right after a round that
  did: the previous round's optimum, started from exactly, is one that more control points did
  not improve on. In the cases measured the rounds after such a round found nothing faster
  either (ur5 and panda around a box: the rounds of 5 and 7 control points both end above the
  4-point round's 0.950284 s and 0.880976 s; stopping after the 5-point round saves 3,000 and
  3,500 of 6,000 and 6,234 evaluations, the answers unchanged). A round that gains anything,
  however little, is followed by another (the Geering arm's round of 11 control points around
  its sphere gains 0.07 %, the next 0.37 %), and so is a round that follows one that gained
  nothing: with no obstacle, the Geering arm's first round ends above its fitted seed (1.0228
  against 1.0152 s, its objective on the optimization grid lower), and the rounds after it reach
  0.9773 s. A round whose path fails the dense checks or cannot be timed decides nothing: the
  rounds go on as after the round before it.

Penalties. The distance penalty acts on a lower bound of the distance between the optimization
samples of the obstacle check (``obstacle_samples`` configurations): from the distances d_i,
d_i+1 at the ends of an interval and a bound M on how far any point of the arm moves in it
(sum over joints of the joint's reach times |dq_j|), the distance inside is at least
(d_i + d_i+1 - M) / 2. Its shortfall below ``clearance + margin`` enters as an exact (L1)
penalty: the largest shortfall times ``obstacle_weight`` (s/m) plus their mean. Joints with a
finite range get the same on how far the samples leave it. Each round's result is then
checked by the planner's own dense clearance check (``check_clearance``) and the joint ranges
at the timing's grid; a round whose result fails it is not accepted.

The seed (m, n_dof) is fitted first, by least squares at chord-length values of s with the end
points fixed, by a spline of ``LocalSettings.first_control_points``.
"""

from __future__ import annotations

import time

import numpy as np

from toptraj.planners.collision.clearance import Clearance, PathInCollision, check_clearance
from toptraj.planners.collision.obstacles import Obstacle
from toptraj.planners.collision.self_collision import SelfCollision, check_self_collision
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath, InvalidRequest
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.search.local_objective import AllowanceSpent, Objective
from toptraj.planners.generators.search.local_outcome import LocalOptimum, LocalRound, LocalSettings, LocalStatistics
from toptraj.planners.generators.search.simplex import compiled_nelder_mead
from toptraj.planners.paths.bspline import DEGREE, BSplinePath, clamped_knots, insert_knot
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing.base import TimeScaling
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.robots import JointLimits, Robot


def dyadic_knots(count: int) -> np.ndarray:
    """The first ``count`` interior knots in insertion order: 1/2; 1/4, 3/4; 1/8, 7/8, 3/8,
    5/8; 1/16, 15/16, ... (each level from the ends inwards, in symmetric pairs)."""
    knots: list[float] = []
    pairs: list[tuple[int, ...]]
    level = 1
    while len(knots) < count:
        denominator = 2**level
        odd = list(range(1, denominator, 2))
        pairs = [(odd[i], odd[-1 - i]) for i in range(len(odd) // 2)] or [(odd[0],)]
        for pair in pairs:
            knots += [p / denominator for p in pair]
        level += 1
    return np.array(knots[:count])


def _schedule(first: int, most: int) -> list[int]:
    """Control-point counts of the rounds: ``first``, then first + 1 if that leaves the knots
    symmetric, then two more each round, up to ``most``."""
    counts = [first]
    while counts[-1] < most:
        interior = counts[-1] - DEGREE - 1
        step = 1 if interior == 0 else 2
        counts.append(min(counts[-1] + step, most))
    return counts


def fit_seed(seed: np.ndarray, interior: np.ndarray) -> np.ndarray:
    """Control points (len(interior) + 4, n_dof) of the clamped cubic through ``seed``'s first
    and last rows closest, in least squares at chord-length values of s, to the rest of them."""
    lengths = np.linalg.norm(np.diff(seed, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(lengths)]) / lengths.sum()
    s[-1] = 1.0  # exactly, whatever the rounding of the sum
    # several points per seed segment, so a seed with few rows still fixes every control point
    dense = np.unique(np.concatenate([s, np.linspace(0.0, 1.0, 4 * (len(interior) + 4))]))
    points = np.column_stack([np.interp(dense, s, seed[:, j]) for j in range(seed.shape[1])])
    from scipy.interpolate import BSpline

    basis = BSpline.design_matrix(dense, clamped_knots(interior), DEGREE).toarray()
    rhs = points - np.outer(basis[:, 0], seed[0]) - np.outer(basis[:, -1], seed[-1])
    inner, *_ = np.linalg.lstsq(basis[:, 1:-1], rhs, rcond=None)
    return np.vstack([seed[0], inner, seed[-1]])


def _exact(path: BSplinePath, robot, limits, kinds, deadline) -> TimeScaling | None:
    """The phase-plane timing (default tolerance and refinement) along ``path``, or ``None``
    when no timing can follow it."""
    constraints = build_path_constraints(path, robot, limits, kinds, path_grid(path), deadline)
    try:
        return PhasePlaneMethod().solve(constraints, deadline=deadline)
    except InfeasiblePath:
        return None


def _clear(path, robot, limits, obstacles, clearance, deadline) -> tuple[bool, Clearance | None]:
    """Whether ``path`` keeps ``clearance`` (the planner's dense check) and its joint ranges (at
    the default grid); the clearance found."""
    q = path(path_grid(path))
    if robot.outside_position_limits(q) is not None:
        return False, None
    try:
        check_self_collision(path, robot, deadline=deadline)
    except SelfCollision:
        return False, None
    if not obstacles:
        return True, None
    try:
        return True, check_clearance(path, robot, list(obstacles), clearance, deadline, explain=False)
    except PathInCollision:
        return False, None


def optimize_locally(
    robot: Robot,
    seed: np.ndarray,
    limits: JointLimits,
    kinds: tuple[str, ...] = ("torque",),
    obstacles: tuple[Obstacle, ...] | list[Obstacle] = (),
    clearance: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
    settings: LocalSettings = LocalSettings(),
    allowance_s: float | None = None,
) -> LocalOptimum:
    """The time-optimal B-spline near ``seed`` (module docstring).

    Args:
        robot: The arm.
        seed: Joint configurations from start to goal, shape (m, n_dof), m >= 2 (a grid path,
            or just start and goal), in joint units.
        limits: The limits the timing holds (``kinds`` of them: "velocity", "acceleration",
            "torque"; ``position_lower``/``upper`` become the range penalty).
        obstacles: World-frame obstacles; every link keeps ``clearance`` (m) from them.
        deadline: Checked at every objective evaluation and in the exact timings.
        settings: Rounds, grid, penalties and Nelder-Mead's budget.
        allowance_s: Seconds the rounds may take (``None``: no limit besides ``deadline``):
            once spent, the round under way ends at its best point so far, is timed and checked
            like any other, and no round follows (``stopped``: "allowance spent").

    Returns:
        The best round's path, its exact duration and timing, control points and statistics.

    Raises:
        InvalidRequest: a seed of the wrong shape or with non-finite values.
        InfeasiblePath: no round gives a path that a timing can follow and that keeps the
            clearance and the joint ranges (a ``PathInCollision`` when it is the clearance).
        BudgetExceeded: ``deadline`` passed.
    """
    started = time.perf_counter()
    seed = _seed_points(seed, robot.dof)
    counts = _schedule(max(settings.first_control_points, DEGREE + 1), settings.max_control_points)
    _check_grid(settings, counts)
    objective = Objective(robot, limits, kinds, seed[0], seed[-1], obstacles, clearance, settings, deadline)
    extent = np.maximum(np.ptp(seed, axis=0) * settings.step, settings.min_step)
    control, seed_duration, best = _fitted_seed(objective, seed, counts[0])
    if allowance_s is not None:
        objective.stop_at = time.monotonic() + allowance_s
    rounds, best, stopped = _rounds(objective, control, counts, extent, best)
    if best is None:
        raise InfeasiblePath(
            f"the local optimization found no path that a timing can follow and that keeps the clearance "
            f"and the joint ranges: the fitted seed and {len(rounds)} rounds of up to {counts[len(rounds) - 1] if rounds else counts[0]} "
            "control points"
        )
    duration, path, timing, found = best
    statistics = LocalStatistics(objective.evaluations, tuple(rounds), float(seed_duration), stopped, time.perf_counter() - started)
    return LocalOptimum(path, float(duration), timing, path.control, path.interior, found, statistics)


#: The best path so far: (exact duration in s, path, timing, clearance found).
_Best = tuple[float, BSplinePath, TimeScaling, Clearance | None]


def _seed_points(seed: np.ndarray, dof: int) -> np.ndarray:
    """The seed's configurations (m, dof), repeated ones dropped."""
    seed = np.asarray(seed, dtype=float)
    if seed.ndim != 2 or seed.shape[0] < 2 or seed.shape[1] != dof or not np.all(np.isfinite(seed)):
        raise InvalidRequest("seed", seed.shape, rule="seed_shape",
                             detail=f"the seed path must be finite joint configurations of shape (m >= 2, {dof}): {seed.shape}")
    keep = np.concatenate([[True], np.linalg.norm(np.diff(seed, axis=0), axis=1) > 1e-12])
    seed = seed[keep]
    if len(seed) < 2:
        raise InvalidRequest("seed", None, rule="seed_ends_coincide", detail="the seed path's start and goal coincide")
    return seed


def _check_grid(settings: LocalSettings, counts: list[int]) -> None:
    """The optimization grid holds the dyadic knots of the largest round (8 intervals per knot
    interval)."""
    if settings.grid_intervals & (settings.grid_intervals - 1):
        raise InvalidRequest("local.grid_intervals", settings.grid_intervals, rule="not_a_power_of_two",
                             detail=f"the optimization grid must have a power of two of intervals; got {settings.grid_intervals}")
    if 8 * (counts[-1] - DEGREE) > settings.grid_intervals:
        raise InvalidRequest(
            "local.grid_intervals", settings.grid_intervals, rule="grid_too_coarse",
            detail=f"{counts[-1]} control points need at least {8 * (counts[-1] - DEGREE)} grid intervals (8 per knot interval)",
        )


def _fitted_seed(objective: Objective, seed: np.ndarray, count: int) -> tuple[np.ndarray, float, _Best | None]:
    """The spline of ``count`` control points fitted to ``seed``: its control points, its exact
    duration (s, ``inf`` when no timing can follow it), and itself as the best path so far when
    it is timed and keeps the clearance and the joint ranges."""
    robot, limits, kinds, deadline = objective.robot, objective.limits, objective.kinds, objective.deadline
    objective.interior = np.sort(dyadic_knots(count - DEGREE - 1))
    control = fit_seed(seed, objective.interior)
    path = BSplinePath(control, objective.interior)
    timing = _exact(path, robot, limits, kinds, deadline)
    if timing is None:
        return control, np.inf, None
    clear, found = _clear(path, robot, limits, objective.obstacles, objective.clearance, deadline)
    return control, timing.duration, (timing.duration, path, timing, found) if clear else None


def _rounds(
    objective: Objective, control: np.ndarray, counts: list[int], extent: np.ndarray, best: _Best | None
) -> tuple[list[LocalRound], _Best | None, str]:
    """The rounds, one per control point count of ``counts`` (``control`` the fitted seed's,
    ``extent`` (n_dof,) the first simplex's steps), until the duration stops improving, the
    counts run out or the allowance is spent: the rounds, the best path and why they stopped."""
    settings, deadline = objective.settings, objective.deadline
    rounds: list[LocalRound] = []
    stopped, stalls = "most control points", 0
    gained = False  # whether the last round that was timed and clear set a new best path
    for number, count in enumerate(counts):
        deadline.progress(number / len(counts), f"local optimization: {count} control points")
        while len(control) < count:
            knots, control = insert_knot(clamped_knots(objective.interior), control, dyadic_knots(len(control) - DEGREE)[-1])
            objective.interior = knots[DEGREE + 1 : -DEGREE - 1]
        before = objective.evaluations
        x, value, spent = _nelder_mead(objective, control[1:-1].ravel(), extent * (1.0 if number == 0 else 0.5))
        if x is None:
            stopped = "allowance spent"
            break
        path = objective.path(x)
        control = path.control
        timing = _exact(path, objective.robot, objective.limits, objective.kinds, deadline)
        clear, found = _clear(path, objective.robot, objective.limits, objective.obstacles, objective.clearance, deadline)
        duration = np.inf if timing is None else timing.duration
        rounds.append(LocalRound(count, float(value), float(duration), clear, objective.evaluations - before))
        fruitless = False  # a timed, clear round no faster than the best, right after one that gained
        if timing is not None and clear:
            stalls = stalls + 1 if best is not None and duration > best[0] * (1.0 - settings.improvement) else 0
            improved = best is None or duration < best[0]
            fruitless, gained = gained and not improved, improved
            if improved:
                best = (duration, path, timing, found)
        if spent:
            stopped = "allowance spent"
            break
        if stalls >= settings.patience or fruitless:
            stopped = "converged"
            break
    return rounds, best, stopped


def _nelder_mead(objective: Objective, x0: np.ndarray, extent: np.ndarray) -> tuple[np.ndarray | None, float, bool]:
    """One round of Nelder-Mead from ``x0`` (the interior control points, flattened), its first
    simplex stepping ``extent`` (n_dof,) along each joint: the best point and its objective, and
    whether the allowance was spent (the best point so far, ``None`` when there is none)."""
    settings = objective.settings
    simplex = np.vstack([x0, x0 + np.diag(np.tile(extent, len(x0) // len(extent)))])
    maxfev, adaptive = settings.evaluations_per_variable * len(x0), len(x0) > 4
    if objective.fused:
        return compiled_nelder_mead(objective, simplex, maxfev, 1e-4, 1e-6, adaptive)
    from scipy.optimize import minimize  # here: scipy's optimizers take a second to import

    objective.round_begins()
    try:
        result = minimize(
            objective,
            x0,
            method="Nelder-Mead",
            options={
                "initial_simplex": simplex,
                "maxfev": maxfev,
                "xatol": 1e-4,
                "fatol": 1e-6,
                "adaptive": adaptive,
            },
        )
    except AllowanceSpent:
        value, x = objective.best
        return x, value, True
    return result.x, float(result.fun), False
