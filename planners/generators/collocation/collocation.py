"""Direct collocation of a free motion from start to goal at rest (Jeong & Lee section 4, after
Geering et al.; Yamamoto et al. section 5): joint positions, velocities and accelerations at
K + 1 instants of a free duration T, minimizing T or the integral of (1 + beta |tau|^2) dt under
torque, velocity and joint-range limits.

Between instants the acceleration is linear in time, so the motion is a C2 piecewise cubic
integrated exactly:

    q_k+1 = q_k + h v_k + h^2 (2 a_k + a_k+1) / 6,    v_k+1 = v_k + h (a_k + a_k+1) / 2,

with h = T / K, and the torque at each instant is the robot's own inverse dynamics,
tau_k = RNEA(q_k, v_k, a_k) from its Pinocchio model (URDF), with exact first derivatives from
Pinocchio's analytical RNEA derivatives. The initial guesses are solved on a coarse grid by
SLSQP (scipy), a dense sequential quadratic programming method fed with those gradients; the
best is refined on the requested grid by IPOPT, whose sparse KKT system keeps fine grids and
many joints affordable (``toptraj.planners.generators.collocation.sparse``; SLSQP again should IPOPT fail).

Several initial guesses are tried: the straight joint line to the goal and, for continuous
joints, to the goal shifted by +-2 pi (the elbow turning a full revolution, as in the Geering
arm's larger moves), each also bent mid-way one joint at a time, and each timed time-optimally
along itself by the phase-plane method; all are solved on a coarse grid and the best is refined.
"""

from __future__ import annotations

import dataclasses
import itertools
import time
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline, Progress
from toptraj.planners.execution.isolated import LOW_PRIORITY, run_isolated
from toptraj.planners.generators.collocation.guesses import bend_guesses, goal_guesses
from toptraj.planners.generators.collocation.motion import CollocationResult
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.paths.waypoints import SplinePath
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.path_checks import check_within_joint_limits
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.robots import JointLimits, Robot


class _Problem:
    """The collocation NLP: z = [T, q (K+1, n), v (K+1, n), a (K+1, n)] flattened."""

    def __init__(self, robot: Robot, limits: JointLimits, motion: FreeMotion, goal: np.ndarray, beta: float):
        self.robot, self.limits, self.beta = robot, limits, beta
        self.n, self.K = robot.dof, motion.intervals
        self.start, self.goal = motion.start, goal
        zero = np.zeros(self.n)
        self.v_start = zero if motion.start_velocity is None else motion.start_velocity
        self.v_end = zero if motion.end_velocity is None else motion.end_velocity
        self.weights = np.ones(self.K + 1)
        self.weights[[0, -1]] = 0.5
        self._cache_key = None

    def unpack(self, z):
        n, K = self.n, self.K
        size = (K + 1) * n
        q = z[1 : 1 + size].reshape(K + 1, n)
        v = z[1 + size : 1 + 2 * size].reshape(K + 1, n)
        a = z[1 + 2 * size :].reshape(K + 1, n)
        return z[0], q, v, a

    def pack(self, T, q, v, a):
        return np.concatenate([[T], q.ravel(), v.ravel(), a.ravel()])

    def _dynamics(self, z):
        """tau (K+1, n) and its derivatives with respect to q, v, a at every instant."""
        if self._cache_key is not None and np.array_equal(self._cache_key, z):
            return self._cache
        _, q, v, a = self.unpack(z)
        model, data = self.robot.model, self.robot.data
        configurations = self.robot.configuration(q)
        tau = np.empty_like(q)
        dq, dv, da = (np.empty((self.K + 1, self.n, self.n)) for _ in range(3))
        for k in range(self.K + 1):
            pin.computeRNEADerivatives(model, data, configurations[k], v[k], a[k])
            tau[k] = pin.rnea(model, data, configurations[k], v[k], a[k])
            dq[k], dv[k] = data.dtau_dq, data.dtau_dv
            mass = data.M
            da[k] = np.triu(mass) + np.triu(mass, 1).T
        self._cache_key, self._cache = z.copy(), (tau, dq, dv, da)
        return self._cache

    # Objective ------------------------------------------------------------------------------
    def cost(self, z):
        T = z[0]
        if self.beta == 0.0:
            return T
        tau = self._dynamics(z)[0]
        return T / self.K * np.sum(self.weights * (1.0 + self.beta * np.sum(tau**2, axis=1)))

    def cost_gradient(self, z):
        gradient = np.zeros_like(z)
        if self.beta == 0.0:
            gradient[0] = 1.0
            return gradient
        T = z[0]
        tau, dq, dv, da = self._dynamics(z)
        gradient[0] = self.cost(z) / T
        factor = (T / self.K) * self.weights[:, None] * 2.0 * self.beta * tau
        size = (self.K + 1) * self.n
        gradient[1 : 1 + size] = np.einsum("ki,kij->kj", factor, dq).ravel()
        gradient[1 + size : 1 + 2 * size] = np.einsum("ki,kij->kj", factor, dv).ravel()
        gradient[1 + 2 * size :] = np.einsum("ki,kij->kj", factor, da).ravel()
        return gradient

    # Equalities: exact integration of piecewise-linear accelerations, and the boundary states --
    def defects(self, z):
        T, q, v, a = self.unpack(z)
        h = T / self.K
        position = q[1:] - q[:-1] - h * v[:-1] - h**2 * (2 * a[:-1] + a[1:]) / 6
        velocity = v[1:] - v[:-1] - h * (a[:-1] + a[1:]) / 2
        ends = np.concatenate([q[0] - self.start, q[-1] - self.goal, v[0] - self.v_start, v[-1] - self.v_end])
        return np.concatenate([position.ravel(), velocity.ravel(), ends])

    def defects_jacobian(self, z):
        T, q, v, a = self.unpack(z)
        n, K = self.n, self.K
        h = T / K
        size = (K + 1) * n
        rows = 2 * K * n + 4 * n
        J = np.zeros((rows, z.size))
        eye = np.eye(n)
        for k in range(K):
            r = k * n
            qk, qk1 = 1 + k * n, 1 + (k + 1) * n
            vk, vk1 = 1 + size + k * n, 1 + size + (k + 1) * n
            ak, ak1 = 1 + 2 * size + k * n, 1 + 2 * size + (k + 1) * n
            J[r : r + n, qk1 : qk1 + n] = eye
            J[r : r + n, qk : qk + n] = -eye
            J[r : r + n, vk : vk + n] = -h * eye
            J[r : r + n, ak : ak + n] = -(h**2) / 3 * eye
            J[r : r + n, ak1 : ak1 + n] = -(h**2) / 6 * eye
            J[r : r + n, 0] = (-v[k] - 2 * h * (2 * a[k] + a[k + 1]) / 6) / K
            r2 = K * n + k * n
            J[r2 : r2 + n, vk1 : vk1 + n] = eye
            J[r2 : r2 + n, vk : vk + n] = -eye
            J[r2 : r2 + n, ak : ak + n] = -h / 2 * eye
            J[r2 : r2 + n, ak1 : ak1 + n] = -h / 2 * eye
            J[r2 : r2 + n, 0] = -(a[k] + a[k + 1]) / 2 / K
        base = 2 * K * n
        J[base : base + n, 1 : 1 + n] = eye
        J[base + n : base + 2 * n, 1 + K * n : 1 + (K + 1) * n] = eye
        J[base + 2 * n : base + 3 * n, 1 + size : 1 + size + n] = eye
        J[base + 3 * n : base + 4 * n, 1 + size + K * n : 1 + size + (K + 1) * n] = eye
        return J

    # Inequalities: |tau| <= limit at every instant ----------------------------------------------
    def torque_margin(self, z):
        tau = self._dynamics(z)[0]
        return np.concatenate([(self.limits.torque - tau).ravel(), (self.limits.torque + tau).ravel()])

    def torque_margin_jacobian(self, z):
        _, dq, dv, da = self._dynamics(z)
        n, K = self.n, self.K
        size = (K + 1) * n
        J = np.zeros(((K + 1) * n, z.size))
        for k in range(K + 1):
            r = k * n
            J[r : r + n, 1 + k * n : 1 + (k + 1) * n] = dq[k]
            J[r : r + n, 1 + size + k * n : 1 + size + (k + 1) * n] = dv[k]
            J[r : r + n, 1 + 2 * size + k * n : 1 + 2 * size + (k + 1) * n] = da[k]
        return np.vstack([-J, J])

    def bounds(self) -> list[tuple[float | None, float | None]]:
        """SciPy's bounds of z: T in [1e-3, 1e3] s, then the joint ranges, velocities and
        accelerations at every grid point (``None``: unbounded)."""
        K = self.K
        lower, upper = self.limits.position_lower, self.limits.position_upper
        velocity = self.limits.velocity
        box: list[tuple[float | None, float | None]] = [(1e-3, 1e3)]
        box += [(lo if np.isfinite(lo) else None, hi if np.isfinite(hi) else None) for lo, hi in zip(np.tile(lower, K + 1), np.tile(upper, K + 1))]
        box += [(-v if np.isfinite(v) else None, v if np.isfinite(v) else None) for v in np.tile(velocity, K + 1)]
        acceleration = self.limits.acceleration
        box += [(-v if np.isfinite(v) else None, v if np.isfinite(v) else None) for v in np.tile(acceleration, K + 1)]
        return box


COARSE_INTERVALS = 12
#: Goals whose best coarse solution costs at most this fraction more than the best one are
#: refined on the fine grid too (at most ``MAX_RIVALS`` of them).
RIVAL_MARGIN = 0.02
MAX_RIVALS = 2


def _timed_guess(problem: _Problem, bend: np.ndarray) -> np.ndarray:
    """The bent line timed time-optimally along itself (phase-plane method, torque and velocity
    limits): a dynamically feasible first guess whose duration bounds the optimum from above."""
    sigma = np.linspace(0.0, 1.0, 25)
    points = problem.start + np.outer(sigma, problem.goal - problem.start) + np.outer(np.sin(np.pi * sigma), bend)
    path = SplinePath(points)
    kinds = ("torque", "velocity") if np.all(np.isfinite(problem.limits.velocity)) else ("torque",)
    constraints = build_path_constraints(path, problem.robot, problem.limits, kinds, path_grid(path, 200))
    timing = PhasePlaneMethod(max_refinements=0).solve(constraints)
    t = np.linspace(0.0, timing.duration, problem.K + 1)
    s, sd, sdd = timing.at_times(t)
    geometry = path.evaluate(s)
    return problem.pack(
        timing.duration,
        geometry.q,
        geometry.dq * sd[:, None],
        geometry.dq * sdd[:, None] + geometry.ddq * (sd**2)[:, None],
    )


def _refined(coarse: _Problem, z: np.ndarray, fine: _Problem) -> np.ndarray:
    """The coarse solution resampled at the fine instants (exactly, on its piecewise cubic)."""
    T, q, v, a = coarse.unpack(z)
    h = T / coarse.K
    t = np.linspace(0.0, T, fine.K + 1)
    k = np.clip((t / h).astype(int), 0, coarse.K - 1)
    r = (t - k * h)[:, None]
    jerk = (a[k + 1] - a[k]) / h
    return fine.pack(
        T,
        q[k] + v[k] * r + a[k] * r**2 / 2 + jerk * r**3 / 6,
        v[k] + a[k] * r + jerk * r**2 / 2,
        a[k] + jerk * r,
    )


def _solve(problem: _Problem, z0: np.ndarray, max_iterations: int):
    from scipy.optimize import minimize  # here: scipy's optimizers take a second to import

    result = minimize(
        problem.cost,
        z0,
        jac=problem.cost_gradient,
        method="SLSQP",
        bounds=problem.bounds(),
        constraints=[
            {"type": "eq", "fun": problem.defects, "jac": problem.defects_jacobian},
            {"type": "ineq", "fun": problem.torque_margin, "jac": problem.torque_margin_jacobian},
        ],
        options={"maxiter": max_iterations, "ftol": 1e-10},
    )
    return result, _feasible(problem, result.x)


def _feasible(problem: _Problem, z: np.ndarray) -> bool:
    """Whether ``z`` meets the equalities and the torque limits (Pinocchio's RNEA) within 1e-6."""
    return bool(np.abs(problem.defects(z)).max() < 1e-6 and problem.torque_margin(z).min() > -1e-6)


def optimize_motion(
    robot: Robot, limits: JointLimits, motion: FreeMotion, torque_weight: float = 0.0, deadline: Deadline = NO_DEADLINE,
    max_iterations: int = 1000, uninterruptible: Callable[..., CollocationResult] | None = None,
) -> CollocationResult:
    """Minimize T (``torque_weight`` = 0) or the integral of (1 + beta |tau|^2) dt from start to
    goal. Every initial guess (goal shifts times bends) is first solved on a coarse grid of
    ``COARSE_INTERVALS``; the best is then refined on ``motion.intervals``.

    SLSQP holds the interpreter for seconds at a time and cannot check a deadline, so under a
    ``deadline`` the optimization runs in a worker process that is killed when it passes
    (``toptraj.planners.execution.isolated``), at a lower CPU priority; with ``uninterruptible``
    (the runner's ``Execution.uninterruptible``) the runner decides where it runs. It reports its
    progress to ``deadline.progress``: each initial guess ("collocation: guess 3 of 15"), then
    the refinement.

    Raises:
        InvalidRequest: a start or goal outside the joint limits.
        InfeasiblePath: no initial guess leads to a feasible motion.
        BudgetExceeded: ``deadline`` passed.
    """
    if uninterruptible is not None:
        return uninterruptible(_optimize_motion, robot, limits, motion, torque_weight, max_iterations, progress=True)
    return run_isolated(
        _optimize_motion, robot, limits, motion, torque_weight, max_iterations, deadline=deadline, progress=True,
        nice=LOW_PRIORITY,
    )


def _optimize_motion(
    robot: Robot,
    limits: JointLimits,
    motion: FreeMotion,
    torque_weight: float,
    max_iterations: int,
    progress: Progress = NO_DEADLINE.progress,
) -> CollocationResult:
    """``optimize_motion``'s work, in the calling process: every initial guess on the coarse
    grid, then the best of each goal within ``RIVAL_MARGIN`` of the best refined on
    ``motion.intervals``; the cheapest refined motion, the others as its ``rivals``."""
    check_within_joint_limits(robot, "start", motion.start)
    check_within_joint_limits(robot, "goal", motion.goal)
    started = time.perf_counter()
    coarse = _coarse_solutions(robot, limits, motion, torque_weight, max_iterations, progress)
    finished: list[CollocationResult] = []
    failures = []
    for rank, contender in enumerate(coarse.contenders):
        progress((coarse.guesses + rank / len(coarse.contenders)) * coarse.share, "collocation: refining the best guess")
        refined = _refine(robot, limits, motion, torque_weight, max_iterations, coarse.dynamics, contender)
        if isinstance(refined, str):
            failures.append(refined)
        else:
            finished.append(dataclasses.replace(refined, solve_s=time.perf_counter() - started))
    if not finished:
        raise InfeasiblePath("the collocation did not converge on the fine grid from its best guess " + "; ".join(failures))
    finished.sort(key=lambda result: result.cost)
    return dataclasses.replace(finished[0], rivals=tuple(finished[1:]))


class _Coarse(NamedTuple):
    """The coarse grid's outcome: the ``contenders`` to refine, each (result, problem, label,
    goal), best first; the CasADi inverse dynamics built for them; the number of guesses and
    the share of the progress each took."""

    contenders: list[tuple]
    dynamics: object
    guesses: int
    share: float


def _coarse_solutions(
    robot: Robot, limits: JointLimits, motion: FreeMotion, torque_weight: float, max_iterations: int, progress: Progress
) -> _Coarse:
    """Every initial guess (goals times bends) solved on ``COARSE_INTERVALS`` by the sparse
    solver; the best feasible one of each goal, those within ``RIVAL_MARGIN`` of the best kept
    (at most ``1 + MAX_RIVALS``).

    Raises:
        InfeasiblePath: no guess leads to a feasible coarse motion (the detail lists each).
    """
    # here: casadi and its solvers take a second to import, for this method only
    from toptraj.planners.generators.collocation.sparse import SparseCollocation
    from toptraj.planners.generators.collocation.symbolic_dynamics import inverse_dynamics_function

    tried: list[str] = []
    coarse_solver, dynamics = None, None
    coarse_motion = FreeMotion(
        motion.start, motion.goal, motion.start_velocity, motion.end_velocity, min(COARSE_INTERVALS, motion.intervals)
    )
    guesses = list(itertools.product(goal_guesses(robot, motion), bend_guesses(robot.dof)))
    # Progress: a dense SQP step costs about the cube of the variables, so the refinement
    # weighs (fine / coarse intervals)^3 coarse guesses.
    share = 1.0 / (len(guesses) + (motion.intervals / coarse_motion.intervals) ** 3)
    per_goal: dict[str, tuple] = {}  # the best coarse solution per goal: (result, problem, label, goal)
    for index, ((goal_label, goal), (bend_label, bend)) in enumerate(guesses):
        progress(index * share, f"collocation: guess {index + 1} of {len(guesses)}")
        label = goal_label + bend_label
        coarse = _Problem(robot, limits, coarse_motion, goal, torque_weight)
        try:
            z0 = _timed_guess(coarse, bend)
        except (InfeasiblePath, TimingFailed) as error:
            tried.append(f"{label}: {error.detail}")
            continue
        if coarse_solver is None:  # one sparse solver for every guess: they differ in bounds only
            dynamics = inverse_dynamics_function(robot)
            coarse_solver = SparseCollocation(coarse, max_iterations, dynamics)
        result = coarse_solver.solve(coarse, z0)
        tried.append(f"{label}: {result.message} (cost {result.fun:.6g})")
        if _feasible(coarse, result.x) and (goal_label not in per_goal or result.fun < per_goal[goal_label][0].fun):
            per_goal[goal_label] = (result, coarse, label, goal)
    if not per_goal:
        raise InfeasiblePath("the collocation found no feasible motion from any initial guess: " + "; ".join(tried))
    # The coarse grid's error (about 1e-3 of T on the Geering arm) exceeds the difference
    # between two goals near the boundary of their optimality regions (Jeong & Lee's phi_b =
    # 0.76): the best of every goal within RIVAL_MARGIN of the best is refined too, and the
    # fine grid decides among them.
    ranked = sorted(per_goal.values(), key=lambda entry: entry[0].fun)
    contenders = [entry for entry in ranked if entry[0].fun <= ranked[0][0].fun * (1.0 + RIVAL_MARGIN)][: 1 + MAX_RIVALS]
    return _Coarse(contenders, dynamics, len(guesses), share)


def _refine(
    robot: Robot, limits: JointLimits, motion: FreeMotion, torque_weight: float, max_iterations: int, dynamics, contender: tuple
) -> CollocationResult | str:
    """The coarse ``contender`` (result, problem, label, goal) resampled on ``motion.intervals``
    and solved by IPOPT (by SLSQP from the same start should IPOPT end infeasible): the motion,
    or why it failed."""
    from toptraj.planners.generators.collocation.sparse import solve_sparse

    coarse_result, coarse, label, goal = contender
    problem = _Problem(robot, limits, motion, goal, torque_weight)
    z0 = _refined(coarse, coarse_result.x, problem)
    result = solve_sparse(problem, z0, max_iterations, dynamics)
    feasible = _feasible(problem, result.x)
    if not feasible:  # the dense SQP, from the same start
        result, feasible = _solve(problem, z0, max_iterations)
    if not feasible:
        return f"({label}): {result.message}"
    T, q, v, a = problem.unpack(result.x)
    tau = problem._dynamics(result.x)[0]
    return CollocationResult(
        t=np.linspace(0.0, T, problem.K + 1), q=q.copy(), v=v.copy(), a=a.copy(), tau=tau.copy(),
        cost=float(result.fun), status=str(result.message), iterations=int(coarse_result.nit + result.nit),
        initial_guess=label, solve_s=0.0, coarse_cost=float(coarse_result.fun), coarse_intervals=coarse.K,
    )

