"""Switching times of a bang-bang free motion, refined by a direct switching-time
parameterization (Jeong & Lee section 4.3, after Geering et al. 1986: the time-optimal motions
of the two-link arm are bang-bang, each torque at one bound or the other between its switching
times, and the paper's figure captions print those times).

A collocation (``toptraj.planners.generators.collocation.collocation``) places a switch only between two of its
instants: it changes sides somewhere within one interval h = T / K (36 ms at K = 30 on the
Geering arm), and reading the instant where the interpolated torque crosses zero leaves errors
of a good part of h. Here the controls are instead exactly bang-bang,

    u_j(t) = sign_j,i * tau_max,j     for  t_j,i-1 <= t < t_j,i,

with the signs sign_j,i taken from the collocation, and the unknowns are the switching times
t_j,i of every joint and the duration T. The motion is integrated forward from the start state
by Pinocchio's forward dynamics (``pinocchio.aba``, a classical Runge-Kutta step on each arc
between consecutive switches of any joint, so that no step straddles a switch), and the goal
state q(T) = q_b, v(T) = v_b gives 2 n equations. With as many unknowns as equations (Type 1
of the paper: 3 switches and T) they are solved by Newton's method on a finite-difference
Jacobian (``root_finding.newton``). With one unknown more (Types 2 to 4: 4 switches and T),
one switching time p is held while Newton's method solves for the others, and T(p) is minimized
by the secant method on dT/dp from the implicit function theorem
(``root_finding.secant_minimum``); with still more, the Newton solution seeds a minimization of
T under the goal equations (SLSQP): the switching-time optimization.

Near a change of type (the paper's Types 1 and 2 at phi_b = 0.98) two switching structures
give almost the same T; ``refine_switching`` therefore also tries the neighbouring structures
(a boundary arc of one joint removed, or a short one added) and keeps the shortest motion that
meets the goal.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.collocation.bang_bang import BangBang, collocation_switches, pruned
from toptraj.planners.generators.collocation.motion import CollocationResult
from toptraj.planners.generators.collocation.root_finding import held_newton, jacobian, newton, secant_minimum
from toptraj.planners.generators.via_points import ConstantSpeedTiming, ViaPath
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.robots import JointLimits, Robot

#: Longest Runge-Kutta step (s) while the switching times are solved for, and of the final
#: integration of the refined motion.
SOLVE_STEP = 8e-3
FINAL_STEP = 1e-3
#: Largest goal error (rad, rad/s) of an accepted refinement.
GOAL_TOLERANCE = 1e-8
#: Duration (s) of a boundary arc added when neighbouring structures are tried.
NEW_ARC = 0.01


@dataclass(frozen=True)
class SwitchedMotion:
    """A refined bang-bang motion: its controls, and its states at instants t (n_t,) that include
    every switch (a switching instant appears twice, before and after): q, v, a (n_t, n_dof) in
    rad, rad/s, rad/s^2, and tau (n_t, n_dof) in N m; the goal error it leaves (rad, rad/s)."""

    controls: BangBang
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    goal_error: float
    solve_step_duration: float | None = None

    @property
    def duration(self) -> float:
        return self.controls.duration

    @property
    def optimality_gap(self) -> float | None:
        """Estimated relative distance of T from the optimum of its switching structure: the
        change of T between the Runge-Kutta steps of the solve (``SOLVE_STEP``) and of the
        answer (``FINAL_STEP``), which bounds the finer step's error from above (fourth order:
        its error is about 1/500 of that change). ``None`` when unknown."""
        if self.solve_step_duration is None:
            return None
        return abs(self.solve_step_duration - self.duration) / self.duration

    @property
    def gap_basis(self) -> str:
        """How ``optimality_gap`` was obtained."""
        if self.solve_step_duration is None:
            return "none"
        return (
            f"second integration: the switching times solved with {SOLVE_STEP * 1e3:g} ms Runge-Kutta steps against "
            f"{FINAL_STEP * 1e3:g} ms (the switching structure itself is the fastest of those tried)"
        )


class _Shooting:
    """The forward integration of bang-bang controls from a start state."""

    def __init__(self, robot: Robot, torque_limit, start, start_velocity, deadline: Deadline = NO_DEADLINE):
        self.robot, self.limit, self.deadline = robot, np.asarray(torque_limit, dtype=float), deadline
        self.start, self.start_velocity = np.asarray(start, float), np.asarray(start_velocity, float)
        self.data = robot.model.createData()

    def acceleration(self, q, v, tau):
        robot = self.robot
        configuration = np.empty(robot.model.nq)
        configuration[robot._plain_q_index] = q[robot._plain_v_index]
        angles = q[robot._angle_index_of_pair]
        configuration[robot._cos_index] = np.cos(angles)
        configuration[robot._cos_index + 1] = np.sin(angles)
        return pin.aba(robot.model, self.data, configuration, v, tau)

    def arcs(self, controls: BangBang):
        """Instants (n_arcs + 1,) where any joint switches, with the torque (n_dof,) on each arc."""
        times = np.concatenate([[0.0], *controls.switches, [controls.duration]])
        edges = np.unique(np.clip(times, 0.0, controls.duration))
        torques = []
        for begin, end in zip(edges[:-1], edges[1:]):
            middle = 0.5 * (begin + end)
            torques.append(
                np.array([signs[np.searchsorted(switches, middle)] for signs, switches in zip(controls.signs, controls.switches)])
                * self.limit
            )
        return edges, torques

    def run(self, controls: BangBang, step: float, keep: bool = False):
        """The end state (q, v) after T; with ``keep``, also every step's (t, q, v, a, tau)."""
        self.deadline.check()
        q, v = self.start.copy(), self.start_velocity.copy()
        edges, torques = self.arcs(controls)
        record = []
        for begin, end, tau in zip(edges[:-1], edges[1:], torques):
            length = end - begin
            if length <= 0.0:
                continue
            n = max(1, int(np.ceil(length / step)))
            h = length / n
            for k in range(n):
                a1 = self.acceleration(q, v, tau)
                if keep:
                    record.append((begin + k * h, q, v, a1, tau))
                q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
                a2 = self.acceleration(q2, v2, tau)
                q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
                a3 = self.acceleration(q3, v3, tau)
                q4, v4 = q + h * v3, v + h * a3
                a4 = self.acceleration(q4, v4, tau)
                q = q + h / 6 * (v + 2 * v2 + 2 * v3 + v4)
                v = v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
            if keep:
                record.append((end, q, v, self.acceleration(q, v, tau), tau))
        return q, v, record


def _solve(shooting: _Shooting, seed: BangBang, goal, goal_velocity) -> tuple[BangBang, float] | None:
    """Switching times and T that reach the goal, the shortest such when there are more unknowns
    than goal equations, and T as solved on the coarser ``SOLVE_STEP`` (for the estimate of the
    integration's error, ``SwitchedMotion.optimality_gap``); ``None`` when the goal is not met
    or the switches leave their order.

    With one unknown more than equations (the paper's Types 2 to 4), one switching time p is
    held while Newton's method solves for the others and T, and T(p) is minimized by the secant
    method on dT/dp (from the implicit function theorem on the same Jacobian, dT/dp = -(J_y^-1
    J_p)_T); with more, by SLSQP under the goal equations."""
    target = np.concatenate([goal, goal_velocity])
    counts = [len(s) for s in seed.switches]

    def residual(theta, step=SOLVE_STEP):
        q, v, _ = shooting.run(seed.with_unknowns(theta), step)
        return np.concatenate([q, v]) - target

    def ordering(theta):
        """Each joint's switches in order within (0, T): differences that must stay >= 0."""
        gaps, offset, T = [], 0, theta[-1]
        for count in counts:
            times = np.concatenate([[0.0], theta[offset : offset + count], [T]])
            gaps.append(np.diff(times))
            offset += count
        return np.concatenate(gaps)

    theta = newton(residual, seed.unknowns(), 1e-9)
    if np.abs(residual(theta)).max() > 1e-6 or ordering(theta).min() < -1e-9:
        return None
    free = len(theta) - len(target)
    held: int | np.ndarray | None = None
    if free == 1:
        theta, held = secant_minimum(residual, theta)
    elif free > 1:
        from scipy.optimize import minimize  # here: scipy's optimizers take a second to import

        theta = minimize(
            lambda x: x[-1],
            theta,
            jac=lambda x: np.eye(len(x))[-1],
            method="SLSQP",
            constraints=[
                {"type": "eq", "fun": residual, "jac": lambda x: jacobian(residual, x, residual(x))},
                {"type": "ineq", "fun": ordering},
            ],
            options={"maxiter": 100, "ftol": 1e-12},
        ).x
        held = np.arange(len(target), len(theta) - 1)
    solve_step_duration = float(theta[-1])
    # Polished on the final step, the held switching times (if any) where they were chosen.
    if held is None:
        theta = newton(lambda x: residual(x, FINAL_STEP), theta, GOAL_TOLERANCE)
    else:
        theta = held_newton(lambda x, h=held: residual(x, FINAL_STEP), theta, np.atleast_1d(held), GOAL_TOLERANCE)
    if ordering(theta).min() < -1e-9 or np.abs(residual(theta, FINAL_STEP)).max() > 1e-6:
        return None
    return seed.with_unknowns(theta), solve_step_duration


def _neighbours(seed: BangBang) -> list[BangBang]:
    """The seed, and the structures one boundary arc away: per joint, its first or last arc
    removed (when it has more than one), or a short arc of the other sign added at either end."""
    options = [seed]
    T = seed.duration
    for j, (signs, switches) in enumerate(zip(seed.signs, seed.switches)):
        variants = []
        if len(signs) > 1:
            variants.append((signs[1:], switches[1:]))
            variants.append((signs[:-1], switches[:-1]))
        variants.append((np.concatenate([[-signs[0]], signs]), np.concatenate([[NEW_ARC], switches])))
        variants.append((np.concatenate([signs, [-signs[-1]]]), np.concatenate([switches, [T - NEW_ARC]])))
        for new_signs, new_switches in variants:
            options.append(
                BangBang(
                    seed.signs[:j] + (new_signs,) + seed.signs[j + 1 :],
                    seed.switches[:j] + (np.asarray(new_switches, float),) + seed.switches[j + 1 :],
                    T,
                )
            )
    return options


def refine_switching(
    robot: Robot,
    torque_limit: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    seed: BangBang,
    start_velocity: np.ndarray | None = None,
    goal_velocity: np.ndarray | None = None,
    neighbours: bool = False,
    deadline: Deadline = NO_DEADLINE,
) -> SwitchedMotion | None:
    """The bang-bang motion from ``start`` to ``goal`` (rad; rest unless velocities are given,
    rad/s) with the switching structure of ``seed`` (or, with ``neighbours``, of the structure
    one boundary arc away that gives the shortest duration), its switching times and duration
    solved for from ``seed``'s; ``None`` when no structure reaches the goal."""
    zero = np.zeros(robot.dof)
    start_velocity = zero if start_velocity is None else np.asarray(start_velocity, float)
    goal_velocity = zero if goal_velocity is None else np.asarray(goal_velocity, float)
    shooting = _Shooting(robot, torque_limit, start, start_velocity, deadline)
    best: tuple[BangBang, float] | None = None
    for candidate in _neighbours(seed) if neighbours else [seed]:
        try:
            solved = _solve(shooting, candidate, np.asarray(goal, float), goal_velocity)
        except (ValueError, np.linalg.LinAlgError):
            solved = None
        if solved is not None and (best is None or solved[0].duration < best[0].duration - 1e-9):
            best = solved
    if best is None:
        return None
    motion = _motion(shooting, pruned(best[0]), np.asarray(goal, float), goal_velocity)
    return dataclasses.replace(motion, solve_step_duration=best[1])


def refine_collocation(
    robot: Robot, limits: JointLimits, motion: FreeMotion, collocation: CollocationResult, deadline: Deadline = NO_DEADLINE
) -> SwitchedMotion | None:
    """The time-optimal (beta = 0) collocation's motion refined to exact bang-bang controls,
    seeded by the switches read off its torques, both the first zero crossing between two
    saturated sides and every crossing (``collocation_switches``), the shorter refined motion
    kept; ``None`` where that does not apply (friction, unlimited torques) or neither reaches the
    goal."""
    frictionless = not robot.has_friction
    if not frictionless or not np.all(np.isfinite(limits.torque)):
        return None
    best = None
    seeds: list[BangBang] = []
    for every_crossing in (False, True):
        seed = collocation_switches(collocation.t, collocation.tau, limits.torque, every_crossing=every_crossing)
        if any(seed.label() == other.label() for other in seeds):
            continue
        seeds.append(seed)
        refined = refine_switching(
            robot, limits.torque, motion.start, collocation.q[-1], seed, motion.start_velocity, motion.end_velocity,
            deadline=deadline,
        )
        if refined is not None and (best is None or refined.duration < best.duration):
            best = refined
    return best


def _motion(shooting: _Shooting, controls: BangBang, goal, goal_velocity) -> SwitchedMotion:
    q, v, record = shooting.run(controls, FINAL_STEP, keep=True)
    error = float(np.abs(np.concatenate([q - goal, v - goal_velocity])).max())
    t, qs, vs, accelerations, torques = (np.array(column) for column in zip(*record))
    return SwitchedMotion(controls, t, qs, vs, accelerations, torques, error)


#: Spacing (s) of the quintic Hermite pieces that carry a refined motion into an answer.
PIECE = 5e-3


def switched_path(motion: SwitchedMotion) -> tuple[ViaPath, ConstantSpeedTiming]:
    """The refined motion as a path in time with constant-speed timing: quintic Hermite pieces
    through its integrated states (q, v, a at both ends of each piece, about ``PIECE`` long, with
    a piece boundary at every switch, where the accelerations jump)."""
    t = motion.t
    boundaries = np.flatnonzero(np.diff(t) == 0.0)  # the last record of an arc, before its switch
    keep, begin = [], 0
    for end in [*boundaries, len(t) - 1]:
        arc = np.arange(begin, end + 1)
        stride = max(1, int(PIECE * (len(arc) - 1) / max(t[end] - t[begin], 1e-12)))
        chosen = arc[::stride]
        keep.append(chosen if chosen[-1] == end else np.append(chosen, end))
        begin = end + 1
    pieces = []
    for indices in keep:
        for i, j in zip(indices[:-1], indices[1:]):
            pieces.append((i, j))
    h = np.array([t[j] - t[i] for i, j in pieces])
    coefficients = np.stack(
        [_quintic(motion.q[i], motion.v[i], motion.a[i], motion.q[j], motion.v[j], motion.a[j], t[j] - t[i]) for i, j in pieces]
    )
    path = ViaPath(coefficients, h)
    return path, ConstantSpeedTiming(path.total, path.knots)


def _quintic(q0, v0, a0, q1, v1, a1, h):
    """Coefficients (n_dof, 6) in local time of the quintic with these end states."""
    d = q1 - q0 - v0 * h - a0 * h**2 / 2
    e = v1 - v0 - a0 * h
    f = a1 - a0
    c3 = (10 * d - 4 * e * h + f * h**2 / 2) / h**3
    c4 = (-15 * d + 7 * e * h - f * h**2) / h**4
    c5 = (6 * d - 3 * e * h + f * h**2 / 2) / h**5
    return np.stack([q0, v0, a0 / 2, c3, c4, c5], axis=1)


