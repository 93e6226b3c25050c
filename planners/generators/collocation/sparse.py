"""The collocation NLP of ``toptraj.planners.generators.collocation.collocation`` solved by IPOPT (Wachter & Biegler,
*Math. Program.* 106, 2006), an interior-point method on the sparse KKT system, through CasADi,
which ships IPOPT and MUMPS in its wheel and differentiates the problem exactly (Hessian
included) from ``toptraj.planners.generators.collocation.symbolic_dynamics``.

The same variables, constraints and cost as the dense problem (``_Problem``): z = [T, q, v, a]
at K + 1 instants, the exact integration of piecewise-linear accelerations as equalities,
|tau_k| <= tau_max at every instant, joint ranges and velocity and acceleration limits as
bounds, and the cost T or T/K sum_k w_k (1 + beta |tau_k|^2). A dense SQP (SLSQP) pays for
the full Jacobian and a dense QP at every step, cubic in the number of variables; here each
instant couples only with its neighbours, so the cost grows about linearly with K: ur5 at 30
intervals, and much finer meshes, become affordable (``benchmarks/free_path.py``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from toptraj.planners.generators.collocation.symbolic_dynamics import inverse_dynamics_function

if TYPE_CHECKING:
    from toptraj.planners.generators.collocation.collocation import _Problem


@dataclass(frozen=True)
class SparseResult:
    """What the collocation reads from a solve (as from scipy's ``OptimizeResult``)."""

    x: np.ndarray
    fun: float
    message: str
    nit: int
    success: bool


def _finite(values: np.ndarray) -> np.ndarray:
    return np.where(np.isfinite(values), values, np.inf)


class SparseCollocation:
    """IPOPT on the collocation NLP of one shape (robot, limits, K, beta), built once and solved
    from as many starts and for as many boundary states as needed: the boundary states are
    bounds of the first and last instants' variables, not part of the expressions.

    Args:
        problem: A ``collocation._Problem`` of that shape.
        max_iterations: IPOPT's iteration cap per solve.
        dynamics: The robot's ``inverse_dynamics_function``, when already built.
    """

    def __init__(self, problem: _Problem, max_iterations: int, dynamics: ca.Function | None = None):
        n, K = problem.n, problem.K
        self.n, self.K = n, K
        size = (K + 1) * n
        # The decision vector is a matrix expression (MX) and the inverse dynamics one function
        # of (q, v, a) mapped over the instants: CasADi differentiates (Hessian included) the
        # small scalar graph of one RNEA once, not the K + 1 copies an SX expression of the
        # whole problem would hold (ur5 at 30 intervals: 0.2 s to build the solver instead of
        # 1.4 s, with the same iterates).
        z = ca.MX.sym("z", 1 + 3 * size)
        T = z[0]
        q = ca.reshape(z[1 : 1 + size], n, K + 1)
        v = ca.reshape(z[1 + size : 1 + 2 * size], n, K + 1)
        a = ca.reshape(z[1 + 2 * size :], n, K + 1)
        h = T / K
        position = q[:, 1:] - q[:, :-1] - h * v[:, :-1] - h**2 * (2 * a[:, :-1] + a[:, 1:]) / 6
        velocity = v[:, 1:] - v[:, :-1] - h * (a[:, :-1] + a[:, 1:]) / 2
        dynamics = inverse_dynamics_function(problem.robot) if dynamics is None else dynamics
        tau = dynamics.map(K + 1)(q, v, a)
        equalities = ca.vertcat(ca.vec(position), ca.vec(velocity))
        limit = np.tile(_finite(np.asarray(problem.limits.torque, dtype=float)), K + 1)
        if problem.beta == 0.0:
            cost = T
        else:
            weights = ca.DM(problem.weights).T
            cost = h * ca.sum2(weights * (1 + problem.beta * ca.sum1(tau**2)))
        bounds = problem.bounds()
        self.lower = np.array([-np.inf if lo is None else lo for lo, _ in bounds])
        self.upper = np.array([np.inf if hi is None else hi for _, hi in bounds])
        self.lbg = np.concatenate([np.zeros(equalities.shape[0]), -limit])
        self.ubg = np.concatenate([np.zeros(equalities.shape[0]), limit])
        options: dict = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": int(max_iterations),
            "ipopt.tol": 1e-10,
            "ipopt.constr_viol_tol": 1e-10,
        }
        self.solver = ca.nlpsol("collocation", "ipopt", {"x": z, "f": cost, "g": ca.vertcat(equalities, ca.vec(tau))}, options)

    def solve(self, problem: _Problem, z0: np.ndarray) -> SparseResult:
        """The optimum from ``z0`` for the boundary states of ``problem`` (same shape)."""
        n, K = self.n, self.K
        size = (K + 1) * n
        lower, upper = self.lower.copy(), self.upper.copy()
        for offset, value in ((1, problem.start), (1 + K * n, problem.goal), (1 + size, problem.v_start),
                              (1 + size + K * n, problem.v_end)):
            lower[offset : offset + n] = upper[offset : offset + n] = value
        solution = self.solver(x0=np.clip(z0, lower, upper), lbx=lower, ubx=upper, lbg=self.lbg, ubg=self.ubg)
        stats = self.solver.stats()
        return SparseResult(
            x=np.array(solution["x"]).ravel(),
            fun=float(solution["f"]),
            message=f"IPOPT: {stats['return_status']}",
            nit=int(stats.get("iter_count", 0)),
            success=bool(stats.get("success", False)),
        )


def solve_sparse(problem: _Problem, z0: np.ndarray, max_iterations: int, dynamics: ca.Function | None = None) -> SparseResult:
    """Solve ``problem`` (a ``collocation._Problem``) from ``z0`` with IPOPT."""
    return SparseCollocation(problem, max_iterations, dynamics).solve(problem, z0)
