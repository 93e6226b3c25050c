"""The collocation NLP of ``planners.free_path.collocation`` solved by IPOPT (Wachter & Biegler,
*Math. Program.* 106, 2006), an interior-point method on the sparse KKT system, through CasADi,
which ships IPOPT and MUMPS in its wheel and differentiates the problem exactly (Hessian
included) from ``planners.free_path.symbolic_dynamics``.

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

import casadi as ca
import numpy as np

from planners.free_path.symbolic_dynamics import inverse_dynamics_function


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


def solve_sparse(problem, z0: np.ndarray, max_iterations: int, max_seconds: float | None = None) -> SparseResult:
    """Solve ``problem`` (a ``collocation._Problem``) from ``z0`` with IPOPT.

    Args:
        problem: The collocation problem (robot, limits, boundary states, K, beta).
        z0: Initial guess, the problem's variable layout.
        max_iterations: IPOPT's iteration cap.
        max_seconds: Wall-clock cap of the solve (IPOPT's ``max_wall_time``), s.
    """
    n, K = problem.n, problem.K
    size = (K + 1) * n
    z = ca.SX.sym("z", z0.size)
    T = z[0]
    q = ca.reshape(z[1 : 1 + size], n, K + 1)
    v = ca.reshape(z[1 + size : 1 + 2 * size], n, K + 1)
    a = ca.reshape(z[1 + 2 * size :], n, K + 1)
    h = T / K
    position = q[:, 1:] - q[:, :-1] - h * v[:, :-1] - h**2 * (2 * a[:, :-1] + a[:, 1:]) / 6
    velocity = v[:, 1:] - v[:, :-1] - h * (a[:, :-1] + a[:, 1:]) / 2
    ends = ca.vertcat(q[:, 0] - problem.start, q[:, K] - problem.goal, v[:, 0] - problem.v_start, v[:, K] - problem.v_end)
    tau = inverse_dynamics_function(problem.robot).map(K + 1)(q, v, a)
    equalities = ca.vertcat(ca.vec(position), ca.vec(velocity), ends)
    torque = ca.vec(tau)
    limit = np.tile(_finite(np.asarray(problem.limits.torque, dtype=float)), K + 1)
    if problem.beta == 0.0:
        cost = T
    else:
        weights = ca.DM(problem.weights).T
        cost = h * ca.sum2(weights * (1 + problem.beta * ca.sum1(tau**2)))
    bounds = problem.bounds()
    lower = np.array([-np.inf if lo is None else lo for lo, _ in bounds])
    upper = np.array([np.inf if hi is None else hi for _, hi in bounds])
    options: dict = {
        "print_time": False,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.max_iter": int(max_iterations),
        "ipopt.tol": 1e-10,
        "ipopt.constr_viol_tol": 1e-10,
    }
    if max_seconds is not None:
        options["ipopt.max_wall_time"] = max(float(max_seconds), 1e-3)
    solver = ca.nlpsol("collocation", "ipopt", {"x": z, "f": cost, "g": ca.vertcat(equalities, torque)}, options)
    solution = solver(
        x0=np.clip(z0, lower, upper),
        lbx=lower,
        ubx=upper,
        lbg=np.concatenate([np.zeros(equalities.shape[0]), -limit]),
        ubg=np.concatenate([np.zeros(equalities.shape[0]), limit]),
    )
    stats = solver.stats()
    return SparseResult(
        x=np.array(solution["x"]).ravel(),
        fun=float(solution["f"]),
        message=f"IPOPT: {stats['return_status']}",
        nit=int(stats.get("iter_count", 0)),
        success=bool(stats.get("success", False)),
    )
