"""The limit gate every answer passes: a timing is checked on a dense resampling
(``toptraj.planners.checks.limit_check``); where a limit is exceeded, the grid is refined there and the path
timed again; a timing that still exceeds a limit, or that cannot be refined, is refused with the
place, the joint and the limit.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from toptraj.planners.checks.accuracy import REFINE_ROUNDS, estimated, finer_constraints
from toptraj.planners.checks.limit_check import Excess, LimitCheck, check_limits
from toptraj.planners.checks.limit_kernels import utilization_pass
from toptraj.planners.constraints.held_load import holding_facts
from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.constraints.tool_speed import TOOL_KINDS, tool_speeds
from toptraj.planners.constraints.zones import tool_speed_at, zone_factors
from toptraj.planners.errors import InfeasiblePath, LimitExceeded, TimingFailed
from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.timing.base import Boundary, PathTiming, TimeScaling, TimingMethod
from toptraj.planners.timing.laws.law_timing import LawTiming
from toptraj.planners.timing.scaled import solve_well_scaled
from toptraj.robots import JointLimits, Robot

if TYPE_CHECKING:
    from toptraj.planners.execution.deadline import Deadline
    from toptraj.planners.trajectory import Samples

#: What every answer promises: no limit exceeded by more than 0.5 % on a dense resampling of
#: its motion (any resampling, a client's own included). The figure the docs, the CSV and the
#: compare table state.
PROMISED_TOLERANCE = 1.005
#: Largest |value| / limit a returned trajectory may reach on the dense check: tighter than
#: ``PROMISED_TOLERANCE``, since a client's own resampling falls between the check's states.
LIMIT_TOLERANCE = 1.003
#: Rounds of grid refinement where the dense check finds a limit exceeded.
GATE_ROUNDS = 4


class TimedStretch(NamedTuple):
    """One stretch of a path (or the whole path) with its timing, the constraints it was timed
    on, and its dense limit check."""

    stretch: GeometricPath
    timing: PathTiming
    constraints: PathConstraints
    check: LimitCheck


def gate_threshold(margin: float) -> float:
    """Largest |value| / limit the gate lets through, against the limits tightened by
    ``margin``: ``LIMIT_TOLERANCE`` without a margin; with one, never above the untightened
    limit itself."""
    if margin == 0.0:
        return LIMIT_TOLERANCE
    return min(LIMIT_TOLERANCE, (1.0 - 1e-9) / (1.0 - margin))


def _refinement(timing: TimeScaling, intervals: np.ndarray) -> np.ndarray:
    """Points that split each listed grid interval of ``timing`` in four."""
    s = timing.s
    quarters = np.array([0.25, 0.5, 0.75])
    return (s[intervals, None] + quarters * (s[intervals + 1] - s[intervals])[:, None]).ravel()


def gated(
    robot: Robot, path: GeometricPath, method: TimingMethod, constraints: PathConstraints, boundary: Boundary,
    duration: float | None, kinds: tuple[str, ...], limits: JointLimits, threshold: float, deadline: Deadline, grid_given: bool = False,
) -> tuple[PathTiming, PathConstraints, LimitCheck]:
    """Time ``path`` with ``method`` and check every limit on the dense states; where a limit is
    exceeded by more than ``threshold``, refine the grid there and time the path again. Every
    timing carries its estimated gap to the converged optimum (``toptraj.planners.checks.accuracy``); a
    time-optimal one above ``GAP_TARGET`` on a grid the request did not name
    (``grid_given``) is timed again on a finer grid, which replaces it only when it too holds
    the limits.

    Returns:
        (timing, constraints, check): the timing that holds the limits, the constraints it was
        timed on, and its ``LimitCheck``.

    Raises:
        InfeasiblePath: the limits still do not hold after ``GATE_ROUNDS`` refinements, or the
            method's timing cannot be refined; says where, which joint and which limit.
    """
    deadline.progress(0.0, "timing")
    result, finer, spent = _solved(method, constraints, boundary, duration, deadline)
    result, constraints, check = _held(robot, path, method, constraints, result, boundary, duration, kinds, limits, threshold, deadline)
    for _ in range(REFINE_ROUNDS):
        refined = finer_constraints(method, constraints, result, finer, spent, deadline, grid_given or duration is not None)
        if refined is None:
            break
        deadline.progress(0.5, "timing on a finer grid for accuracy")
        try:
            attempt, finer, spent = _solved(method, refined, boundary, duration, deadline)
            result, constraints, check = _held(robot, path, method, refined, attempt, boundary, duration, kinds, limits, threshold, deadline)
        except (InfeasiblePath, TimingFailed):
            break  # the answer on the coarser grid stands, its gap stated
    return result, constraints, check


def _solved(method, constraints, boundary, duration, deadline):
    """``method`` on ``constraints`` with its estimated gap: (timing, a finer grid that holds
    the error where it lies or ``None``, the seconds the solve took)."""
    started = time.perf_counter()
    result = solve_well_scaled(method, constraints, boundary, duration, deadline)
    spent = time.perf_counter() - started
    result, finer = estimated(method, constraints, boundary, result, deadline, spent)
    return result, finer, spent


def _held(robot, path, method, constraints, result, boundary, duration, kinds, limits, threshold, deadline):
    """``result`` through the dense check, refined where it exceeds a limit (``gated``)."""
    for round_ in range(GATE_ROUNDS + 1):
        deadline.check()
        deadline.progress(0.5 + 0.5 * round_ / (GATE_ROUNDS + 1), f"limit check, round {round_ + 1}")
        check = check_limits(path, result, robot, limits, kinds, threshold, constraints.s, constraints)
        if check.worst is None or check.worst.ratio <= threshold:
            return result, constraints, check
        if isinstance(result, LawTiming) and duration is None:
            # The shortest time law was found on samples of its profile; the dense check sees
            # between them. Slowing a law down by a factor f divides velocities by f,
            # accelerations (and the inertial part of torques) by f^2, jerks by f^3.
            power = {"velocity": 1.0, "jerk": 3.0, **dict.fromkeys(TOOL_KINDS, 1.0)}.get(check.worst.kind, 2.0)
            result = result.slowed(check.worst.ratio ** (1.0 / power) * (1 + 1e-6))
            if result is None:
                break
            continue
        if not (isinstance(result, TimeScaling) and constraints.can_refine and check.intervals_over.size):
            break
        extra = _refinement(result, check.intervals_over)
        extra = np.unique(extra[~np.isin(extra, constraints.s)])
        if extra.size == 0:
            break
        constraints = constraints.with_points(extra)
        result, _, _ = _solved(method, constraints, boundary, duration, deadline)
    assert check.worst is not None  # each round that ends the loop found a limit exceeded
    error = limit_exceeded(method.name, check.worst, robot, path)
    held = holding_facts(constraints) if check.worst.kind == "torque" else {}
    if not held:
        raise error
    facts = {key: value for key, value in vars(error).items() if key != "detail"}
    raise LimitExceeded(
        f"the {method.name} timing exceeds the torque limit of joint {facts['joint']!r} by {100 * (facts['ratio'] - 1):.2f} % "
        f"at s = {facts['s']:.4f}: holding the path still needs more torque than the limits somewhere (gravity and "
        "friction), which no timing changes",
        **{**facts, **held},
    )


def limit_exceeded(method: str, worst: Excess, robot: Robot, path: GeometricPath) -> LimitExceeded:
    """The error of ``method``'s timing over a limit: the ``worst`` excess, at its s along the
    path given (a stretch's s mapped back to its parent), its joint named."""
    s = float(getattr(path, "to_parent", lambda x: x)(worst.s))
    joint = None if worst.joint < 0 else robot.joint_names[worst.joint]
    what = f"{worst.kind} limit of joint {joint!r}" if joint is not None else f"{worst.kind.replace('_', ' ')} limit"
    return LimitExceeded(
        f"the {method} timing exceeds the {what} by "
        f"{100 * (worst.ratio - 1):.2f} % at s = {s:.4f}, and refining the grid there did not bring "
        "it back within the limits; use another timing method, a lower limit scale or more grid points",
        s=s,
        joint=joint,
        limit=worst.kind,
        ratio=float(worst.ratio),
        method=method,
    )


def checked(
    robot: Robot, path: GeometricPath, result: PathTiming, method: str, kinds: tuple[str, ...], limits: JointLimits,
    threshold: float, constraints: PathConstraints,
) -> TimedStretch:
    """A timing that cannot be refined, through the limit gate: kept when it holds the limits,
    refused (with where, which joint and which limit) when it does not."""
    check = check_limits(path, result, robot, limits, kinds, threshold, constraints.s)
    if check.worst is not None and check.worst.ratio > threshold:
        raise limit_exceeded(method, check.worst, robot, path)
    return TimedStretch(path, result, constraints, check)


def _zoned(checks: list, limits: JointLimits, s: np.ndarray) -> list:
    """``samples_exceed``'s (kind, values, limit) with each value divided by the zones' factor
    at its sample's s (``toptraj.planners.constraints.zones``) and the tool's linear speed
    against the speed in force there, so that each stands against the limit in force."""
    factors = zone_factors(limits.zones, s)
    factor_of = {"velocity": factors.velocity, "acceleration": factors.acceleration, "torque": factors.torque}
    zoned = []
    for kind, values, limit in checks:
        if kind in factor_of:
            values = values / factor_of[kind][:, None]
        elif kind == "tool" and limits.tool is not None:
            bounds = np.column_stack([tool_speed_at(limits, s, factors), np.full(len(s), limits.tool.angular_speed)])
            values, limit = np.nan_to_num(values / bounds), np.ones(2)
        zoned.append((kind, values, limit))
    return zoned


def samples_exceed(
    samples: Samples, limits: JointLimits, threshold: float, kinds: tuple[str, ...], robot: Robot | None = None, jerk: bool = False
) -> tuple[str, int, int] | None:
    """(kind, sample, joint) of a returned sample beyond ``threshold`` of a gated limit (joint
    -1 for a tool limit, checked when ``robot`` is given). With ``jerk`` (for timings whose
    acceleration is continuous) and the jerk among ``kinds``, the jerk between consecutive
    samples, by finite differences of their accelerations, is checked too: it is the mean of
    the jerk over the step, never above its peak, so it exceeds the limit only where the
    accelerations jump (sample index: the step's first)."""
    checks = [(kind, values, getattr(limits, kind)) for kind, values in
              (("velocity", samples.qd), ("acceleration", samples.qdd), ("torque", samples.tau)) if kind in kinds]
    if jerk and "jerk" in kinds and len(samples.t) > 1:
        steps = np.diff(samples.t)[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            between = np.where(steps > 0.0, np.diff(samples.qdd, axis=0) / steps, 0.0)
        checks.append(("jerk", between, limits.jerk))
    if limits.tool is not None and robot is not None:
        speeds = tool_speeds(robot, limits.tool, samples.q, samples.qd)
        checks.append(("tool", speeds, limits.tool.bounds))  # columns in the order of TOOL_KINDS
    if limits.zones and samples.s is not None:
        checks = _zoned(checks, limits, samples.s)
    for kind, values, limit in checks:
        if not values.size:
            continue
        ratio, sample, joint = utilization_pass(
            np.ascontiguousarray(values, dtype=float), np.asarray(limit, dtype=float), np.inf,
            np.empty(values.shape[1]), np.zeros(len(values), dtype=bool),
        )
        if ratio > threshold:
            if kind == "tool":
                return TOOL_KINDS[int(joint)], int(sample), -1
            return kind, int(sample), int(joint)
    return None
