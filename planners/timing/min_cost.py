"""``min_cost``: the minimum of J = integral of (1 + beta |tau|^2) dt along a given path
(Yamamoto, Marushima & Mohri's minimum-cost trajectory problem, MCTP, eqs. (4), (11), (32)),
solved to its global optimum as a convex program.

In b = sd^2 and a = sdd (constant per grid interval, b_i+1 = b_i + 2 ds a_i), the torque
tau = A a + B b + C is affine, the interval's time is dt_i = 2 ds_i / (sqrt(b_i) + sqrt(b_i+1)),
and with c_i = (sqrt(b_i) + sqrt(b_i+1)) / (2 ds_i), concave in b,

    J = sum_i 1 / c_i + beta |tau_i|^2 / c_i,

a sum of convex functions (1 / concave, and quadratic over concave), as in Verscheure et al.,
"Time-optimal path tracking for robots: a convex optimization approach" (IEEE TAC 2009).
tau_i is taken at the interval's midpoint. The limits are the same rows as for the other methods,
at both ends of every interval. cvxpy states the problem and Clarabel, an interior-point conic
solver, solves it; with beta = 0 it is a third, independent computation of the time-optimal
timing. Joint friction enters the limits (conservatively linearized) and the cost: Coulomb
friction in C, viscous friction d sd = d sqrt(b), concave in b, by its tangent at the maximum
velocity curve (so that the program stays convex, its optimum that of the tangent's cost; where
that tangent leaves no feasible timing, as under strong damping, at speeds 16 times lower, and
then once more at the motion found: ``toptraj.planners.timing.friction``); the
cost reported is that of the motion found with its own torques, the friction as it is
(``motion_cost``).
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass

import numpy as np

from toptraj.planners.constraints.admissible import friction_reference
from toptraj.planners.constraints.linear_rows import LinearRows
from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InfeasiblePath, OutOfRange, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.execution.isolated import LOW_PRIORITY, run_isolated
from toptraj.planners.timing.base import AT_REST, Boundary, TimeScaling, TimingMethod
from toptraj.planners.timing.friction import friction_passes


@dataclass(frozen=True)
class CostTimeScaling(TimeScaling):
    """A ``TimeScaling`` with the cost it reached, J in s (the integral of 1 + beta |tau|^2)."""

    cost: float = float("nan")
    solver_status: str = ""
    #: Seconds of the solve that do not grow with the grid (the worker process started, the
    #: solver imported): what a finer grid's solve is expected to take again, the rest
    #: scaled by its intervals (``toptraj.planners.checks.accuracy.finer_constraints``).
    fixed_seconds: float = 0.0


class MinCostMethod(TimingMethod):
    """Minimum of the integral of (1 + beta |tau|^2) dt along the path (beta in 1/(N m)^2)."""

    name = "min_cost"
    absolute_tolerances = True
    required_kinds = frozenset({"torque"})
    takes_cost = True
    #: cvxpy and Clarabel take about 9 kB per grid interval and joint: 4,000 intervals on a
    #: 6-joint arm is about 210 MB (and some 10 s; 3,000 intervals 153 MB). They cannot check
    #: a deadline: the solve is the method's uninterruptible step.
    bytes_per_interval_joint = 9_000
    interruptible = False
    #: cvxpy's set-up of the program (its expressions are built per joint, not per interval)
    #: takes about as long as solving 150 intervals: ur5's 100 intervals 0.12-0.19 s, 4,096
    #: intervals 3.3 s, once the worker process runs.
    setup_intervals = 150

    def __init__(self, torque_weight: float = 0.0):
        if not (np.isfinite(torque_weight) and torque_weight >= 0.0):
            raise OutOfRange("method.torque_weight", torque_weight, 0.0, float("inf"), "1/(N m)^2", rule="negative_weight")
        self.torque_weight = torque_weight

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> CostTimeScaling:
        """The convex program on ``constraints``' grid (module docstring), the cost reported that
        of the motion's own torques (``motion_cost``: viscous friction as it is, where the
        program holds its tangent)."""
        torque = [column for column, (kind, _) in enumerate(constraints.rows) if kind == "torque"]
        viscous = _midpoint(constraints.d, constraints.d_left, torque) if constraints.has_friction else None
        if viscous is not None and not viscous.any():
            viscous = None

        def solve(reference: np.ndarray) -> tuple[CostTimeScaling, MinCostProgram]:
            return self._solved(constraints, boundary, reference, torque, viscous, deadline)

        if viscous is None:
            result, program = solve(friction_reference(constraints))
        else:  # one solve around the tangent's reference, or, lowered, one more around its answer
            result, program = friction_passes(
                solve, friction_reference(constraints), lambda pair: pair[0].sd**2, lambda pair: pair[0].duration,
                passes=0, lowered_passes=1,
            )
        return dataclasses.replace(result, cost=motion_cost(program, result.sd**2))

    def _solved(self, constraints, boundary, reference, torque, viscous, deadline) -> tuple[CostTimeScaling, MinCostProgram]:
        """One solve, the viscous friction of the rows and of the cost's torques linearized at
        ``reference`` (x = sd^2 at the grid points, 1/s^2)."""
        program = MinCostProgram(
            ds=np.diff(constraints.s),
            x_bound=constraints.sd_max**2,
            right=constraints.linearized(reference),
            left=constraints.linearized(reference, "left"),
            torque_a=_midpoint(constraints.a, constraints.a_left, torque),
            torque_b=_midpoint(constraints.b, constraints.b_left, torque),
            torque_c=_midpoint(constraints.c, constraints.c_left, torque),
            sd_start=boundary.sd_start,
            sd_end=boundary.sd_end,
            torque_weight=self.torque_weight,
            torque_unit=_torque_units(constraints, torque),
            torque_d=viscous,
            viscous_reference=None if viscous is None else 0.5 * (reference[:-1] + reference[1:]),
        )
        deadline.check()
        # cvxpy's canonicalization and Clarabel cannot check a deadline: they run in a child
        # process that is killed when the budget is spent, and whose memory is freed on exit.
        started = time.perf_counter()
        interior, value, status, computing = run_isolated(timed_solve, program, deadline=deadline, nice=LOW_PRIORITY)
        fixed = max(time.perf_counter() - started - computing, 0.0)
        x = np.concatenate(([boundary.sd_start**2], interior, [boundary.sd_end**2]))
        return CostTimeScaling(constraints.s, np.sqrt(x), cost=value, solver_status=status, fixed_seconds=fixed), program


def _midpoint(right: np.ndarray, left: np.ndarray, columns: list[int]) -> np.ndarray:
    """The rows ``columns`` at the middle of each grid interval (n, k): the mean of the right
    side of its start and the left side of its end."""
    return 0.5 * (right[:-1, columns] + left[1:, columns])


def motion_cost(program: MinCostProgram, x: np.ndarray) -> float:
    """J (s) of the motion x = sd^2 at the grid points (n + 1,) in the program's discretization,
    with its own torques, viscous friction d sqrt(x) included exactly: sum over the intervals of
    their time 2 ds / (sqrt(x_i) + sqrt(x_i+1)) times 1 + beta |tau|^2 at their middle, tau =
    a u + b x_mid + c + d sqrt(x_mid), u = (x_i+1 - x_i) / (2 ds). The program's objective where
    it has no viscous friction (its cone constraints are tight at the optimum)."""
    ds, root = program.ds, np.sqrt(np.maximum(x, 0.0))
    with np.errstate(divide="ignore"):
        time = np.where(ds > 0.0, 2.0 * ds / (root[:-1] + root[1:]), 0.0)
    if program.torque_weight == 0.0:
        return float(time.sum())
    u, middle = (x[1:] - x[:-1]) / (2.0 * ds), 0.5 * (x[:-1] + x[1:])
    tau = program.torque_a * u[:, None] + program.torque_b * middle[:, None] + program.torque_c
    if program.torque_d is not None:
        tau = tau + program.torque_d * np.sqrt(np.maximum(middle, 0.0))[:, None]
    return float((time * (1.0 + program.torque_weight * (tau**2).sum(axis=1))).sum())


@dataclass(frozen=True)
class MinCostProgram:
    """The data of the convex program, plain arrays (it is sent to a worker process).

    Attributes:
        ds: Grid intervals, shape (n,).
        x_bound: First-order bound on b = sd^2 at the grid points, shape (n + 1,), in 1/s^2.
        right, left: The linearized limit rows on both sides of each grid point, (n + 1, m).
        torque_a, torque_b, torque_c: Torque coefficients at the interval midpoints, (n, k), one
            column per torque row.
        sd_start, sd_end: Path speed at the ends, in 1/s.
        torque_weight: beta, in 1/(N m)^2.
        torque_unit: A typical torque of each torque row (k,), N m (its limit): the torques
            enter the cone constraints in this unit, so that they are of order one (Clarabel's
            tolerances are absolute; in N m, tau^2 of thousands failed it on fine grids).
        torque_d: Viscous friction coefficients at the interval midpoints (n, k), N m s (the
            torque's term d sd); ``None`` without viscous friction.
        viscous_reference: x at the midpoints (n,), 1/s^2, at which d sqrt(x) is replaced by its
            tangent d (x + x_ref) / (2 sqrt(x_ref)) in the cost's torques.
    """

    ds: np.ndarray
    x_bound: np.ndarray
    right: LinearRows
    left: LinearRows
    torque_a: np.ndarray
    torque_b: np.ndarray
    torque_c: np.ndarray
    sd_start: float
    sd_end: float
    torque_weight: float
    torque_unit: np.ndarray | None = None
    torque_d: np.ndarray | None = None
    viscous_reference: np.ndarray | None = None


def _torque_cost(program: MinCostProgram, a, b, z):
    """beta times the integral of |tau|^2 dt over the grid (cvxpy expressions of the interval
    accelerations ``a`` (n,), the b = sd^2 at the points (n + 1,) and z (n,), module docstring),
    and its rotated second-order cones: w_ij >= (tau_ij / unit_j)^2 / z_i, tau at the middles,
    its viscous friction d sqrt(b) by its tangent at ``program.viscous_reference``."""
    import cvxpy as cp

    n, ds = len(program.ds), program.ds
    middle = 0.5 * (b[:-1] + b[1:])
    units = np.ones(program.torque_a.shape[1]) if program.torque_unit is None else program.torque_unit
    cost, cones = 0.0, []
    for column, unit in enumerate(units):
        tau = (
            cp.multiply(program.torque_a[:, column] / unit, a) + cp.multiply(program.torque_b[:, column] / unit, middle)
            + program.torque_c[:, column] / unit
        )  # in units of ``unit``: w is then (tau / unit)^2 / z
        if program.torque_d is not None and program.viscous_reference is not None:
            root = np.sqrt(np.maximum(program.viscous_reference, 1e-6))
            tau = tau + cp.multiply(program.torque_d[:, column] / (2.0 * unit * root), middle) + (
                program.torque_d[:, column] * root / (2.0 * unit)
            )
        w = cp.Variable(n, nonneg=True)
        cones.append(cp.SOC(w + z, cp.vstack([2 * tau, w - z]), axis=0))
        cost = cost + program.torque_weight * unit**2 * cp.sum(cp.multiply(2 * ds, w))
    return cost, cones


def _torque_units(constraints: PathConstraints, torque: list[int]) -> np.ndarray:
    """(k,) the largest finite torque limit of each torque row along the path (N m), 1 where
    none is finite."""
    bound = np.maximum(np.abs(constraints.upper[:, torque]), np.abs(constraints.lower[:, torque]))
    bound = np.where(np.isfinite(bound), bound, 0.0).max(axis=0, initial=0.0)
    return np.where(bound > 0.0, bound, 1.0)


def timed_solve(program: MinCostProgram) -> tuple[np.ndarray, float, str, float]:
    """``solve_program``'s answer and the seconds it took once the solver was imported (what
    grows with the grid)."""
    import cvxpy  # noqa: F401  (imported before the clock starts: a cost the grid does not change)

    started = time.perf_counter()
    interior, value, status = solve_program(program)
    return interior, value, status, time.perf_counter() - started


def solve_program(program: MinCostProgram) -> tuple[np.ndarray, float, str]:
    """b = sd^2 at the interior grid points (n - 1,), the cost J and the solver status.

    Raises:
        InfeasiblePath: the program is infeasible.
        TimingFailed: the solver failed or stopped short of an optimum.
    """
    import cvxpy as cp

    ds, x_bound = program.ds, program.x_bound
    # Rows of order one (LinearRows.normalized): Clarabel's tolerances are absolute.
    right, left = program.right.normalized(), program.left.normalized()
    n = len(ds)
    # The end values of b are data, not variables: an interior-point solver then never has
    # to sit on the boundary of the cone sqrt(b) >= 0 at a motion that starts from rest.
    interior = cp.Variable(n - 1, nonneg=True)
    b = cp.hstack([np.array([program.sd_start**2]), interior, np.array([program.sd_end**2])])
    a = cp.Variable(n)
    limits = [b[1:] == b[:-1] + 2 * cp.multiply(ds, a)]
    finite = np.isfinite(x_bound[1:-1])
    if finite.any():
        limits.append(interior[finite] <= x_bound[1:-1][finite])
    for rows, index, b_at in ((right, slice(0, n), b[:-1]), (left, slice(1, n + 1), b[1:])):
        for column in range(rows.a.shape[1]):
            value = cp.multiply(rows.a[index, column], a) + cp.multiply(rows.b[index, column], b_at) + rows.c[index, column]
            if np.isfinite(rows.upper[0, column]):
                limits.append(value <= rows.upper[index, column])
            if np.isfinite(rows.lower[0, column]):
                limits.append(value >= rows.lower[index, column])
    # z_i <= sqrt(b_i) + sqrt(b_i+1) is tight at the optimum, so 2 ds_i / z_i is the interval's
    # time and 2 ds_i w_ij, with w_ij >= tau_ij^2 / z_i (a rotated second-order cone), its
    # torque-squared integral. (Scaled so that z and w stay of order one for the solver.)
    z = cp.Variable(n, nonneg=True)
    roots = cp.hstack([np.array([program.sd_start]), cp.sqrt(interior), np.array([program.sd_end])])
    limits.append(z <= roots[:-1] + roots[1:])
    cost = cp.sum(cp.multiply(2 * ds, cp.inv_pos(z)))
    if program.torque_weight > 0:
        torque_cost, cones = _torque_cost(program, a, b, z)
        cost, limits = cost + torque_cost, limits + cones
    problem = cp.Problem(cp.Minimize(cost), limits)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "inaccurate" is reported as the status
            problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        # cvxpy's own advice (another solver, verbose=True) is for its callers, not for a request.
        raise TimingFailed(
            "min_cost's convex solver (Clarabel) failed on this path (as it can where waypoints that nearly repeat "
            "bend the spline sharply between them: drop such waypoints); phase_plane or toppra time the path (the "
            "time-optimal timing, min_cost's torque_weight 0)"
        ) from None
    if problem.status in ("infeasible", "infeasible_inaccurate"):
        raise InfeasiblePath("no timing along the path meets the limits (the convex program is infeasible)")
    if interior.value is None or problem.status not in ("optimal", "optimal_inaccurate"):
        raise TimingFailed(f"the convex solver stopped with status {problem.status!r}")
    return np.maximum(interior.value, 0.0), float(problem.value), str(problem.status)
