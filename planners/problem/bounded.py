"""Limits that bound the motion: a time-optimal timing moves as fast as its limits allow, so
where no limit it holds bounds a joint that moves, the shortest time is zero and there is no
answer to give (the phase plane's maximum velocity curve is infinite there).

A limit of the kinds held (velocity, acceleration, jerk, torque) bounds the path speed wherever
a joint with a finite one moves: velocity directly, acceleration and jerk from rest, torque
through the inertia (M(q) q' is never zero where q' is not); a tool-speed limit bounds it as
well. Refused before planning: a robot none of whose joints has a finite limit of the kinds
held, and a waypoint path with a segment that moves only joints without one.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.errors import InvalidRequest
from toptraj.robots import JointLimits, Robot

#: Kinds whose limits bound the path speed along a path from rest.
BOUNDING_KINDS = ("velocity", "acceleration", "jerk", "torque")


def bounded_joints(limits: JointLimits, kinds: tuple[str, ...]) -> np.ndarray:
    """Which joints (n_dof,) have a finite, positive limit of one of ``kinds``."""
    bounded = np.zeros(len(limits.velocity), dtype=bool)
    for kind in BOUNDING_KINDS:
        if kind in kinds:
            values = np.asarray(getattr(limits, kind), dtype=float)
            bounded |= np.isfinite(values) & (values > 0.0)
    return bounded


def check_speed_bounded(
    robot: Robot, limits: JointLimits, kinds: tuple[str, ...], waypoints: np.ndarray | None = None, field: str = "constraints",
    served: frozenset[str] | tuple[str, ...] | None = None,
) -> None:
    """Refuse a motion that the held ``limits`` of ``kinds`` leave unbounded (module docstring);
    ``waypoints`` (n_waypoints, n_dof), when the path is one through them, are checked segment
    by segment. ``field`` names the input in the error (a cell's arm); ``served``, the kinds the
    method can hold (``None``: all), those the error offers to add.

    Raises:
        InvalidRequest: rule "no_limit_bounds_speed" (no joint bounded; facts: the robot, the
            kinds held and those the robot has finite limits of, among ``served``) or "segment_unbounded" (the
            first segment moving only unbounded joints: its waypoints and those joints).
    """
    if limits.tool is not None:
        return
    bounded = bounded_joints(limits, kinds)
    available = tuple(
        kind for kind in BOUNDING_KINDS if np.any(np.isfinite(getattr(limits, kind))) and (served is None or kind in served)
    )
    if not bounded.any():
        raise InvalidRequest(
            field, list(kinds), rule="no_limit_bounds_speed", robot=robot.name, kinds=tuple(kinds), available=available,
            detail=f"no limit held ({', '.join(kinds) or 'none'}) bounds {robot.name}'s motion: it has no finite limit of those kinds",
        )
    waypoints = None if waypoints is None else np.asarray(waypoints, dtype=float)
    if waypoints is None or waypoints.ndim != 2 or waypoints.shape[0] < 2 or waypoints.shape[1] != len(bounded):
        return  # a path of the wrong shape is refused where the path is built
    moved = np.abs(np.diff(waypoints, axis=0)) > 0.0
    free = np.flatnonzero(moved.any(axis=1) & ~(moved & bounded).any(axis=1))
    if free.size:
        segment = int(free[0])
        joints = tuple(robot.joint_names[j] for j in np.flatnonzero(moved[segment]))
        unbounded = tuple(name for name, limited in zip(robot.joint_names, bounded, strict=True) if not limited)
        raise InvalidRequest(
            field, list(kinds), rule="segment_unbounded", robot=robot.name, kinds=tuple(kinds), available=available,
            segment=segment, joints=joints, unbounded=unbounded,
            detail=f"from waypoint {segment} to {segment + 1} only joints without a limit held move ({', '.join(joints)})",
        )
