"""The dense limit check of a timed path: how close each limit comes to binding, and where a
limit is exceeded.

Along q(s) timed by s(t) (Yamamoto et al. eqs. (8), (9); jerk by one more derivative):

    qd   = q' sd
    qdd  = q' sdd + q'' sd^2
    qddd = q' sddd + 3 q'' sd sdd + q''' sd^3
    tau  = RNEA(q, qd, qdd) + D qd + F sign(qd)

and, when a request limits a tool's speed, |v| and |w| of the frame's twist J(q) qd
(``toptraj.planners.constraints.tool_speed``; the frame velocities are computed only then).

evaluated at the timing's dense states (``PathTiming.dense_states``): for timings on a grid of s,
``POINTS_PER_INTERVAL`` states per interval of the grid the constraints were built on (as far
apart in the intervals a method refined), both ends and both sides of every grid point. This
check is the gate every answer passes: ``toptraj.planners.plan`` refines the grid where it finds a limit
exceeded, and refuses the answer when refinement cannot bring it back.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from toptraj.planners.checks.limit_kernels import utilization_pass
from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.constraints.tool_speed import TOOL_KINDS, tool_speeds
from toptraj.planners.constraints.torque_interpolation import MAX_TRAVEL, dense_torques, grid_travel
from toptraj.planners.constraints.zones import has_tool_zone, tool_speed_at, zone_factors, zone_peaks
from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.timing.base import DenseStates, PathTiming, TimeScaling
from toptraj.robots import JointLimits, Robot

#: States per grid interval for the check, both ends included: the ends and the quarter points.
#: Between two grid points where the rows hold, a limit can be exceeded only by an excursion
#: of second order in the interval's width; a parabolic one, wherever its peak lies, comes
#: within an eighth of the interval of a quarter point, where it shows at least 15/16 of its
#: height (seven states: 35/36, at 1.7 times the dynamics evaluations).
POINTS_PER_INTERVAL = 5
KINDS = ("velocity", "acceleration", "torque", "jerk")
#: Largest estimated error, as a fraction of the joint's torque limit, of a torque interpolated
#: between grid points from the rows (``toptraj.planners.constraints.torque_interpolation``); a state whose estimate
#: is larger gets the RNEA (``Robot.inverse_dynamics``). Far below the gate's ``LIMIT_TOLERANCE`` - 1.
INTERPOLATION_TOLERANCE = 1e-5


@dataclass(frozen=True)
class Excess:
    """The largest |value| / limit of a timed path and where it occurs.

    Attributes:
        ratio: |value| / limit (1.0: the limit binds).
        kind: "velocity", "acceleration", "torque", "jerk", "tool_speed" or
            "tool_angular_speed".
        joint: Joint index (-1 for a tool limit).
        s: Path parameter where it occurs.
    """

    ratio: float
    kind: str
    joint: int
    s: float


@dataclass(frozen=True)
class LimitCheck:
    """Peak utilization per limit kind and joint (shape (n_dof,) each; 0 where unlimited; a
    tool limit's, when one is requested, of shape () under its ``TOOL_KINDS`` name), the worst
    state, and the grid intervals holding a state above the threshold (empty when none,
    or when the timing has no grid). With zones, each limit is the one in force at the state's
    s, and ``zones`` holds {zone index: the peak inside it of the limits it sets}."""

    utilization: dict[str, np.ndarray]
    worst: Excess | None
    intervals_over: np.ndarray
    zones: dict[int, float] = field(default_factory=dict)


def joint_motion(path: GeometricPath, states: DenseStates) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """q, qd, qdd and (when the states carry sddd) qddd at ``states``, each (n, n_dof), with the
    path's one-sided derivatives from the left for ``states.left`` states at a corner or a break
    (and, for the third derivative, at any knot)."""
    points = path.evaluate(states.s, "right")
    q, dq, ddq = points.q, points.dq, points.ddq
    third = path.third_derivative(states.s, "right") if states.sddd is not None else None
    sides = np.concatenate([path.kinks, path.breaks])
    at_kink = states.left & np.isin(states.s, sides) if len(sides) else None
    if at_kink is not None and at_kink.any():
        dq, ddq = dq.copy(), ddq.copy()
        left = path.evaluate(states.s[at_kink], "left")
        dq[at_kink], ddq[at_kink] = left.dq, left.ddq
    if third is not None:
        # d3q/ds3 jumps at every knot of a spline, not only at corners.
        at_knot = states.left & np.isin(states.s, path.knots)
        if at_knot.any():
            third = third.copy()
            third[at_knot] = path.third_derivative(states.s[at_knot], "left")
    sd, sdd = states.sd[:, None], states.sdd[:, None]
    qd = dq * sd
    qdd = dq * sdd + ddq * (sd * sd)
    jerk = None if third is None or states.sddd is None else third * sd**3 + 3.0 * ddq * (sd * sdd) + dq * states.sddd[:, None]
    return q, qd, qdd, jerk


def _at_rest(robot: Robot, path: GeometricPath, states) -> np.ndarray | None:
    """The path's tangent q' (n, n_dof) at the states at rest (zero elsewhere), on the side each
    belongs to, for the sign of Coulomb friction there (``Robot.inverse_dynamics``); ``None``
    without Coulomb friction or a state at rest."""
    rest = states.sd == 0.0
    if not (robot.has_coulomb_friction and rest.any()):
        return None
    direction = np.zeros((len(states.s), robot.dof))
    s, left = states.s[rest], states.left[rest]
    direction[rest] = np.where(left[:, None], path.evaluate(s, "left").dq, path.evaluate(s, "right").dq)
    return direction


def _torques(robot: Robot, states, q, qd, qdd, constraints: PathConstraints | None, direction: np.ndarray | None = None) -> np.ndarray:
    """Joint torques (n, n_dof) at ``states``. At a moving state on the grid of ``constraints``
    (when they hold a torque row for every joint) the torque is the row ``a u + b x + c + d sd``
    the build computed there with the RNEA (the same number, to rounding), on the side
    the state belongs to; between grid points it is interpolated from those rows
    (``toptraj.planners.constraints.torque_interpolation.dense_torques``) where the grid resolves them, the
    interpolation's estimated error is within ``INTERPOLATION_TOLERANCE`` of the limit and no
    joint has Coulomb friction (whose sign, inside c, is the grid point's). The RNEA runs,
    batched, at every other state, Coulomb friction at a state at rest opposing the path's
    tangent ``direction`` there (as the rows hold it)."""
    column = {} if constraints is None else {joint: k for k, (kind, joint) in enumerate(constraints.rows) if kind == "torque"}
    if constraints is None or len(column) != robot.dof:
        return robot.inverse_dynamics(q, qd, qdd, direction)
    columns = np.array([column[joint] for joint in range(robot.dof)], dtype=np.int64)
    travel = grid_travel(constraints)
    interpolate = travel is not None and not robot.has_coulomb_friction
    tau = np.empty_like(qd)
    exact = np.zeros(len(states.s), dtype=bool)
    dense_torques(
        constraints.s, constraints.smooth, (constraints.a, constraints.b, constraints.c, constraints.d),
        (constraints.a_left, constraints.b_left, constraints.c_left, constraints.d_left), columns,
        np.zeros(0) if travel is None else travel, MAX_TRAVEL, np.maximum(constraints.upper[0, columns], -constraints.lower[0, columns]),
        states.s, states.sd, states.sdd, states.left, interpolate, INTERPOLATION_TOLERANCE, tau, exact,
    )
    if exact.any():
        tau[exact] = robot.inverse_dynamics(q[exact], qd[exact], qdd[exact], None if direction is None else direction[exact])
    return tau


def _zoned(limits: JointLimits, s: np.ndarray, values: dict, limit_of: dict, speeds: np.ndarray | None) -> dict[int, float]:
    """Divide ``values`` (per kind, (n, k) at the states ``s``) in place by the zones' factors at
    each state, so that the robot's limits in ``limit_of`` stand for those in force there; the
    tool's linear speed becomes its share of the speed in force (limit 1). Returns the zones'
    peaks against their own limits (``toptraj.planners.constraints.zones.zone_peaks``)."""
    robot_ratios = {}
    for kind in ("velocity", "acceleration", "torque"):
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.abs(values[kind]) / np.asarray(limit_of[kind], dtype=float)
        robot_ratios[kind] = np.nan_to_num(ratio, nan=0.0, posinf=np.inf).max(axis=1, initial=0.0)
    factors = zone_factors(limits.zones, s)
    for kind, factor in (("velocity", factors.velocity), ("acceleration", factors.acceleration), ("torque", factors.torque)):
        values[kind] = values[kind] / factor[:, None]
    if speeds is not None and has_tool_zone(limits):
        robot_ratios["tool_speed"] = speeds[:, 0]  # m/s: against each zone's own speed
        with np.errstate(divide="ignore", invalid="ignore"):
            share = speeds[:, 0] / tool_speed_at(limits, s, factors)
        values["tool_speed"], limit_of["tool_speed"] = np.nan_to_num(share, posinf=np.inf)[:, None], np.ones(1)
    return zone_peaks(limits.zones, s, robot_ratios)


def check_limits(
    path: GeometricPath,
    timing: PathTiming,
    robot: Robot,
    limits: JointLimits,
    kinds: tuple[str, ...] = KINDS,
    threshold: float = np.inf,
    reference: np.ndarray | None = None,
    constraints: PathConstraints | None = None,
) -> LimitCheck:
    """Every limit of ``limits`` (velocity, acceleration, torque, jerk when the timing has a
    finite one, and the tool speeds of ``limits.tool``) over the dense states of ``timing``
    along ``path``.

    Args:
        kinds: The joint limits the timing must hold: ``worst`` and ``intervals_over`` look at
            these (and at the tool limits, always held when requested) only (``utilization``
            reports every kind).
        threshold: Ratio above which a state's grid interval is listed in ``intervals_over``.
        reference: For a timing on a grid of s, the grid the constraints were built on: states
            keep its resolution (``POINTS_PER_INTERVAL`` per interval) where the timing method
            refined it, instead of that many per refined interval.
        constraints: The constraints the timing was computed on: at states on their grid, the
            torque is read from their rows instead of being computed again.
    """
    if reference is not None and isinstance(timing, TimeScaling):
        states = timing.dense_states(POINTS_PER_INTERVAL, reference)
    else:
        states = timing.dense_states(POINTS_PER_INTERVAL)
    q, qd, qdd, jerk = joint_motion(path, states)
    values = {"velocity": qd, "acceleration": qdd, "torque": _torques(robot, states, q, qd, qdd, constraints, _at_rest(robot, path, states))}
    if jerk is not None:
        values["jerk"] = jerk
    limit_of = {kind: getattr(limits, kind) for kind in values}
    speeds = None
    if limits.tool is not None:
        speeds = tool_speeds(robot, limits.tool, q, qd)
        for column, kind in enumerate(TOOL_KINDS):
            if np.isfinite(limits.tool.bounds[column]):
                values[kind], limit_of[kind] = speeds[:, column : column + 1], limits.tool.bounds[column : column + 1]
    peaks = _zoned(limits, states.s, values, limit_of, speeds) if limits.zones else {}
    utilization, worst = {}, None
    over = np.zeros(len(states.s), dtype=bool)
    for kind, value in values.items():
        checked = kind in kinds or kind in TOOL_KINDS
        peak = np.empty(value.shape[1])
        ratio, state, column = utilization_pass(
            np.ascontiguousarray(value, dtype=float), np.asarray(limit_of[kind], dtype=float),
            threshold if checked else np.inf, peak, over,
        )
        utilization[kind] = peak if kind not in TOOL_KINDS else peak.max()
        if checked and len(states.s) and (worst is None or ratio > worst.ratio):
            joint = -1 if kind in TOOL_KINDS else int(column)
            worst = Excess(float(ratio), kind, joint, float(states.s[state]))
    intervals = np.empty(0, dtype=int) if states.interval is None or not over.any() else np.unique(states.interval[over])
    return LimitCheck(utilization, worst, intervals, peaks)
