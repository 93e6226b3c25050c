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
timing. Joint friction enters the limits (conservatively linearized) but not the cost.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from planners.constraints import PathConstraints
from planners.deadline import NO_DEADLINE, Deadline
from planners.errors import InfeasiblePath, TimingFailed
from planners.mvc import friction_reference
from planners.timing.base import AT_REST, Boundary, TimeScaling, TimingMethod


@dataclass(frozen=True)
class CostTimeScaling(TimeScaling):
    """A ``TimeScaling`` with the cost it reached, J in s (the integral of 1 + beta |tau|^2)."""

    cost: float = float("nan")
    solver_status: str = ""


class MinCostMethod(TimingMethod):
    """Minimum of the integral of (1 + beta |tau|^2) dt along the path (beta in 1/(N m)^2)."""

    name = "min_cost"
    absolute_tolerances = True
    required_kinds = frozenset({"torque"})
    takes_cost = True

    def __init__(self, torque_weight: float = 0.0):
        self.torque_weight = torque_weight

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> CostTimeScaling:
        import cvxpy as cp

        s = constraints.s
        ds = np.diff(s)
        n = len(ds)
        x_bound = constraints.sd_max**2
        reference = friction_reference(constraints)
        right, left = constraints.linearized(reference), constraints.linearized(reference, "left")
        # The end values of b are data, not variables: an interior-point solver then never has
        # to sit on the boundary of the cone sqrt(b) >= 0 at a motion that starts from rest.
        interior = cp.Variable(n - 1, nonneg=True)
        b = cp.hstack([np.array([boundary.sd_start**2]), interior, np.array([boundary.sd_end**2])])
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
        roots = cp.hstack([np.array([boundary.sd_start]), cp.sqrt(interior), np.array([boundary.sd_end])])
        limits.append(z <= roots[:-1] + roots[1:])
        cost = cp.sum(cp.multiply(2 * ds, cp.inv_pos(z)))
        if self.torque_weight > 0:
            middle = 0.5 * (b[:-1] + b[1:])
            for column, (kind, _) in enumerate(constraints.rows):
                if kind != "torque":
                    continue
                A = 0.5 * (constraints.a[:-1, column] + constraints.a_left[1:, column])
                B = 0.5 * (constraints.b[:-1, column] + constraints.b_left[1:, column])
                C = 0.5 * (constraints.c[:-1, column] + constraints.c_left[1:, column])
                tau = cp.multiply(A, a) + cp.multiply(B, middle) + C
                w = cp.Variable(n, nonneg=True)
                limits.append(cp.SOC(w + z, cp.vstack([2 * tau, w - z]), axis=0))
                cost = cost + self.torque_weight * cp.sum(cp.multiply(2 * ds, w))
        deadline.check()
        problem = cp.Problem(cp.Minimize(cost), limits)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # "inaccurate" is reported as the status
                problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError as error:
            raise TimingFailed(f"the convex solver failed: {error}") from None
        if problem.status in ("infeasible", "infeasible_inaccurate"):
            raise InfeasiblePath("no timing along the path meets the limits (the convex program is infeasible)")
        if interior.value is None or problem.status not in ("optimal", "optimal_inaccurate"):
            raise TimingFailed(f"the convex solver stopped with status {problem.status!r}")
        x = np.concatenate(([boundary.sd_start**2], np.maximum(interior.value, 0.0), [boundary.sd_end**2]))
        return CostTimeScaling(s, np.sqrt(x), cost=float(problem.value), solver_status=problem.status)
