"""Each arm's limits along a cell's schedule on a dense resampling, and the least uniform slowing
of the clock that brings every one within.

Slowing the clock by k >= 1 (at time t each arm is where its motion was at t / k), with y = 1/k,
scales the velocities as qd y and the accelerations as qdd y^2; the torques (inverse dynamics,
Featherstone 2008, eq. 5.1, tau = M(q) qdd + C(q, qd) qd + g(q), plus the joint friction
D qd + F sign(qd)) become

    tau(y) = (g(q) + F sign(qd)) + D qd y + (tau - g(q) - F sign(qd) - D qd) y^2,

so each limit at each sample is a polynomial in y of degree at most 2, evaluated without a new
inverse dynamics. The largest y in (0, 1] that holds them all is found by bisection; at y -> 0
only the static torque g(q) + F sign(qd) is left, and where that exceeds a limit no slowing helps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from toptraj.planners.coordination.cell import Cell, CellArm
from toptraj.planners.coordination.timing import Schedule
from toptraj.planners.errors import InfeasiblePath
from toptraj.robots.robot import friction_sign

#: Samples of the limit check per second of motion, and at least.
LIMIT_RATE, LIMIT_MIN = 2_000, 4_000
#: Bisection steps on y = 1 / k (the slowing found to about 1e-12 of itself).
BISECTIONS = 45
#: Kinds of limit served in a cell.
KINDS = ("velocity", "acceleration", "torque")


@dataclass(frozen=True)
class ArmLoad:
    """One arm's dense samples split by how each quantity scales with y = 1/k: velocities
    ``qd``, accelerations ``qdd``, and torques ``static + linear y + quadratic y^2``, each
    (n, n_dof); the samples' path parameters ``s`` (n,)."""

    s: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    static: np.ndarray
    linear: np.ndarray
    quadratic: np.ndarray


def cannot_hold_still(index: int, arm: CellArm, s: float, torque: float, joint: int) -> InfeasiblePath:
    """The error of arm ``index``, whose path at ``s`` needs ``torque`` (N m, N on a prismatic
    joint) at rest on joint index ``joint``, above its torque limit, with the facts of what may
    hold it instead: whether its limits are scaled down (``scaled``), whether it carries a
    payload (``carrying``)."""
    name, unit, limit = arm.robot.joint_names[joint], arm.robot.force_units[joint], float(arm.limits.torque[joint])
    carrying = arm.robot.payload is not None
    return InfeasiblePath(
        f"arms[{index}] ({arm.robot.name}): holding its path still at s = {s:.4f} needs {torque:.4g} {unit} on joint {name!r}, "
        f"above its torque limit of {limit:.4g} {unit} (gravity{' and payload' if carrying else ''}): no timing holds it",
        s=s, joint=name, limit="torque", rule="arm_not_held", index=index, robot=arm.robot.name, torque=torque, unit=unit,
        torque_limit=limit, own_limit=float(arm.robot.limits.torque[joint]), scaled=bool(limit < arm.robot.limits.torque[joint]),
        carrying=carrying,
    )


def arm_load(arm: CellArm, s: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> ArmLoad:
    """The arm's samples (each (n, n_dof)) split as ``ArmLoad`` (module docstring)."""
    robot = arm.robot
    # At rest, Coulomb friction opposes the path's tangent, as the arm's planning holds it.
    direction = arm.path.evaluate(s).dq if robot.has_coulomb_friction else None
    tau = robot.inverse_dynamics(q, qd, qdd, direction)
    gravity = robot.rnea(q, np.zeros_like(qd), np.zeros_like(qdd))
    static = gravity + robot.coulomb_friction * friction_sign(qd, direction) if robot.has_friction else gravity
    linear = robot.viscous_friction * qd if robot.has_friction else np.zeros_like(qd)
    return ArmLoad(s, qd, qdd, static, linear, tau - static - linear)


def _utilization(arm: CellArm, load: ArmLoad, kinds: tuple[str, ...], y: float) -> dict[str, np.ndarray]:
    """|quantity| / limit of each kind at the slowing y, per sample and joint (n, n_dof)."""
    limits = arm.limits
    out = {}
    if "velocity" in kinds:
        out["velocity"] = np.abs(load.qd) * y / limits.velocity
    if "acceleration" in kinds:
        out["acceleration"] = np.abs(load.qdd) * y**2 / limits.acceleration
    if "torque" in kinds:
        out["torque"] = np.abs(load.static + load.linear * y + load.quadratic * y**2) / limits.torque
    return out


def peak_utilization(
    cell: Cell, loads: list[ArmLoad], y: float = 1.0, kinds: tuple[str, ...] | None = None
) -> list[dict[str, np.ndarray]]:
    """Per arm, the peak |quantity| / limit of each kind of the cell (or of ``kinds``, those not
    held too) per joint (n_dof,) over the dense samples, at the slowing y."""
    kinds = cell.kinds if kinds is None else kinds
    return [
        {kind: u.max(axis=0) for kind, u in _utilization(arm, load, kinds, y).items()} for arm, load in zip(cell.arms, loads)
    ]


def _holds(cell: Cell, loads: list[ArmLoad], y: float) -> bool:
    return all(float(u.max()) <= 1.0 for peaks in peak_utilization(cell, loads, y) for u in peaks.values())


def dense_loads(cell: Cell, schedule: Schedule) -> list[ArmLoad]:
    """Each arm's ``ArmLoad`` at ``max(LIMIT_MIN, LIMIT_RATE * duration)`` samples of ``schedule``."""
    count = max(LIMIT_MIN, math.ceil(LIMIT_RATE * schedule.duration))
    t = np.linspace(0.0, schedule.duration, count + 1)
    s = schedule.path_parameters(t)
    return [arm_load(arm, s[:, i], *states) for i, (arm, states) in enumerate(zip(cell.arms, schedule.states(cell, t)))]


def _static_failure(cell: Cell, loads: list[ArmLoad]) -> InfeasiblePath | None:
    """The error of a torque that exceeds its limit with the arm held still, or None."""
    if "torque" not in cell.kinds:
        return None
    for index, (arm, load) in enumerate(zip(cell.arms, loads)):
        u = np.abs(load.static) / arm.limits.torque
        if u.max() > 1.0:
            k, j = np.unravel_index(int(np.argmax(u)), u.shape)
            return cannot_hold_still(index, arm, float(load.s[k]), abs(float(load.static[k, j])), int(j))
    return None


def within_limits(cell: Cell, schedule: Schedule) -> Schedule:
    """``schedule`` with its clock slowed by the least k >= 1 that holds every arm's limits on a
    dense resampling (module docstring).

    Raises:
        InfeasiblePath: a torque limit broken even with the arm still, naming the arm, joint and s.
    """
    loads = dense_loads(cell, schedule)
    if _holds(cell, loads, 1.0):
        return schedule
    failure = _static_failure(cell, loads)
    if failure is not None:
        raise failure
    low, high = 0.0, 1.0  # low holds, high does not
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if _holds(cell, loads, middle) else (low, middle)
    if low <= 0.0:
        raise InfeasiblePath("no uniform slowing of the cell's clock holds every arm's limits: lower the arms' speeds")
    return Schedule(schedule.motions, schedule.kind, schedule.stretch / low)
