"""The converged optima of Yamamoto's free path, by a transcription of its own: the references
of ``tests/planners/generators/test_free_path.py`` and ``tests/planners/generators/test_sparse_collocation.py``.

    python benchmarks/yamamoto_reference.py [--intervals 200,400,800,1600]

The motion of ``yamamoto_2r`` from (45, -90) to (-90, 0) degrees, at rest at both ends, under
its torque limits (10 and 5 N m; no other limit), minimizing T (beta = 0) and the integral of
(1 + beta |tau|^2) dt with beta = 0.03 (Yamamoto et al. section 5).

Hermite-Simpson collocation in separated form (Betts, *Practical Methods for Optimal Control*,
2nd ed., section 4.6.6; Kelly 2017, SIAM Review 59(4), eq. 6.4-6.5), independent of the
planner's own piecewise-linear-acceleration transcription (``toptraj.planners.generators.collocation.collocation``):
states x = (q, v), x' = f = (v, a), the acceleration a a control at every node and interval
midpoint, and with h = T / K

    x_mid = (x_k + x_k+1) / 2 + h (f_k - f_k+1) / 8,    x_k+1 - x_k = h (f_k + 4 f_mid + f_k+1) / 6;

the torque tau = RNEA(q, v, a) (the robot's model, ``toptraj.planners.generators.collocation.symbolic_dynamics``,
checked against Pinocchio in ``tests/planners/generators/test_sparse_collocation.py``) within its limits at every
node and midpoint, and the cost integrated by Simpson's rule. Solved by IPOPT (CasADi) from the
straight joint line under a quintic time law. Its error falls as h^4 where the solution is
smooth (the torques switch, so less at the switches): successive halvings of the grid agree
to more digits than the tests ask. Prints, per number of intervals K, the
minimum time T* (s) and the minimum cost J* (s).

Its output (about 20 s on one core):

         K       T* (s)   J* beta=0.03 (s)
       200    0.2059860          0.5514515
       400    0.2059859          0.5514515
       800    0.2059855          0.5514515
      1600    0.2059855          0.5514515

so T* = 0.2059855 s and J* = 0.5514515 s, the references of the tests.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from toptraj import robots  # noqa: E402
from toptraj.planners.generators.collocation.symbolic_dynamics import inverse_dynamics_function  # noqa: E402

START = np.radians([45.0, -90.0])
GOAL = np.radians([-90.0, 0.0])
BETA = 0.03


def solve(intervals: int, beta: float, guess_T: float = 0.3) -> float:
    """The optimum (T* for beta = 0, else J*) on ``intervals`` Hermite-Simpson intervals."""
    robot = robots.load("yamamoto_2r")
    rnea = inverse_dynamics_function(robot)
    n, K = robot.dof, intervals
    limit = robot.limits.torque
    opti = ca.Opti()
    T = opti.variable()
    q, v, a = (opti.variable(n, K + 1) for _ in range(3))
    qm, vm, am = (opti.variable(n, K) for _ in range(3))
    h = T / K
    opti.subject_to([q[:, 0] == START, q[:, K] == GOAL, v[:, 0] == 0, v[:, K] == 0, T >= 1e-3])
    # Hermite-Simpson, separated form: interpolation to the midpoint and Simpson's quadrature.
    opti.subject_to(qm == (q[:, :-1] + q[:, 1:]) / 2 + h * (v[:, :-1] - v[:, 1:]) / 8)
    opti.subject_to(vm == (v[:, :-1] + v[:, 1:]) / 2 + h * (a[:, :-1] - a[:, 1:]) / 8)
    opti.subject_to(q[:, 1:] - q[:, :-1] == h * (v[:, :-1] + 4 * vm + v[:, 1:]) / 6)
    opti.subject_to(v[:, 1:] - v[:, :-1] == h * (a[:, :-1] + 4 * am + a[:, 1:]) / 6)
    tau = rnea.map(K + 1)(q, v, a)
    tau_mid = rnea.map(K)(qm, vm, am)
    for j in range(n):
        opti.subject_to(opti.bounded(-limit[j], tau[j, :], limit[j]))
        opti.subject_to(opti.bounded(-limit[j], tau_mid[j, :], limit[j]))
    if beta == 0.0:
        opti.minimize(T)
    else:
        node = 1 + beta * ca.sum1(tau**2)
        middle = 1 + beta * ca.sum1(tau_mid**2)
        opti.minimize(h / 6 * (ca.sum2(node[:, :-1]) + 4 * ca.sum2(middle) + ca.sum2(node[:, 1:])))
    # Start: the straight joint line under a quintic time law of duration guess_T.
    for tau_grid, (qq, vv, aa) in ((np.linspace(0, 1, K + 1), (q, v, a)), ((np.arange(K) + 0.5) / K, (qm, vm, am))):
        s = 10 * tau_grid**3 - 15 * tau_grid**4 + 6 * tau_grid**5
        ds = (30 * tau_grid**2 - 60 * tau_grid**3 + 30 * tau_grid**4) / guess_T
        dds = (60 * tau_grid - 180 * tau_grid**2 + 120 * tau_grid**3) / guess_T**2
        step = (GOAL - START)[:, None]
        opti.set_initial(qq, START[:, None] + step * s)
        opti.set_initial(vv, step * ds)
        opti.set_initial(aa, step * dds)
    opti.set_initial(T, guess_T)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "tol": 1e-12, "max_iter": 3000, "sb": "yes"})
    solution = opti.solve()
    return float(solution.value(opti.f))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--intervals", default="200,400,800,1600")
    args = parser.parse_args()
    print(f"{'K':>6s} {'T* (s)':>12s} {'J* beta=0.03 (s)':>18s}")
    for K in (int(k) for k in args.intervals.split(",")):
        print(f"{K:6d} {solve(K, 0.0):12.7f} {solve(K, BETA):18.7f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
