"""Limits that bound the motion: a time-optimal timing moves as fast as its limits allow, so
where no limit it holds bounds the path speed, the shortest time is zero and there is no answer
to give (the phase plane's maximum velocity curve is infinite there, with no acceleration row to
bring the motion up to it).

A limit of the kinds held bounds the path speed wherever a joint with a finite one moves:
velocity directly, acceleration, jerk and torque from rest (torque through the inertia, M(q) q',
which couples the joints); a tool-speed limit bounds it too. Two checks:

* ``check_speed_bounded``, before anything is built: a robot none of whose joints has a finite
  limit of the kinds held, without a tool-speed limit of the whole path, is refused at once.
* ``unbounded_stretch``, on the path's constraints: a stretch of the grid (two grid points or
  more in a row) where neither the first-order bound on the path speed nor any row of finite
  bounds acting on the path acceleration (nor a jerk limit of a moving joint) holds: a joint
  without a limit moving alone, a tool-speed zone's outside, a tool turning without moving.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.paths.base import GeometricPath
from toptraj.robots import JointLimits, Robot

#: Kinds whose limits bound the path speed along a path from rest.
BOUNDING_KINDS = ("velocity", "acceleration", "jerk", "torque")


def _available(limits: JointLimits, served: frozenset[str] | tuple[str, ...] | None, joints: np.ndarray | None = None) -> tuple[str, ...]:
    """The kinds (among ``served``; ``None``: all) of which the robot has a finite limit on one
    of ``joints`` (``None``: any joint)."""
    return tuple(
        kind for kind in BOUNDING_KINDS
        if (served is None or kind in served)
        and np.any(np.isfinite(np.asarray(getattr(limits, kind), dtype=float)[slice(None) if joints is None else joints]))
    )


def check_speed_bounded(
    robot: Robot, limits: JointLimits, kinds: tuple[str, ...], field: str = "constraints",
    served: frozenset[str] | tuple[str, ...] | None = None,
) -> None:
    """Refuse a robot none of whose joints has a finite limit of ``kinds`` in ``limits``, where
    no tool-speed limit bounds the whole path either (module docstring). ``field`` names the
    input in the error (a cell's arm); ``served``, the kinds the method can hold (``None``:
    all), those the error offers to add.

    Raises:
        InvalidRequest: rule "no_limit_bounds_speed" (facts: the robot, the kinds held and those
            it has finite limits of, among ``served``).
    """
    tool = limits.tool
    if tool is not None and (np.isfinite(tool.speed) or np.isfinite(tool.angular_speed)):
        return  # where it bounds nothing (a tool turning without moving), ``unbounded_stretch`` says so
    if _available(limits, kinds):  # a joint has a finite limit of a kind held
        return
    raise InvalidRequest(
        field, list(kinds), rule="no_limit_bounds_speed", robot=robot.name, kinds=tuple(kinds), available=_available(limits, served),
        detail=f"no limit held ({', '.join(kinds) or 'none'}) bounds {robot.name}'s motion: it has no finite limit of those kinds",
    )


def unbounded_stretch(constraints: PathConstraints) -> tuple[int, int] | None:
    """The first stretch of grid points (first, last index, last > first) where nothing bounds
    the path speed (module docstring); ``None`` when there is none (a single such point, where a
    limited joint turns back, is bounded by its neighbours)."""
    bounded = np.isfinite(constraints.sd_max)
    if bounded.all():  # the usual case: the speed is bounded everywhere
        return None
    if constraints.a.size:
        finite = np.isfinite(constraints.lower) | np.isfinite(constraints.upper)
        bounded |= ((constraints.a != 0.0) & finite).any(axis=1) | ((constraints.a_left != 0.0) & finite).any(axis=1)
    if constraints.jerk is not None:
        dq, _, _, limit = constraints.jerk
        bounded |= ((np.abs(dq) > 0.0) & np.isfinite(np.asarray(limit, dtype=float))[None, :]).any(axis=1)
    free = ~bounded
    pairs = np.flatnonzero(free[:-1] & free[1:])
    if not pairs.size:
        return None
    first = int(pairs[0])
    last = first + 1
    while last + 1 < len(free) and free[last + 1]:
        last += 1
    return first, last


def check_stretches_bounded(
    constraints: PathConstraints, path: GeometricPath, robot: Robot, limits: JointLimits, kinds: tuple[str, ...],
    s_of: Callable[[float], float] = float, served: frozenset[str] | tuple[str, ...] | None = None, field: str = "constraints",
) -> None:
    """Refuse ``path`` (timed on ``constraints``) where a stretch of it has nothing that bounds
    it (``unbounded_stretch``), naming it by ``s_of`` (the whole path's parameter of the
    stretch's own) and the joints moving there; ``field`` names whose path it is (a cell's
    ``arms[i]``).

    Raises:
        InvalidRequest: rule "stretch_unbounded" (facts: ``s_from``, ``s_to``, the moving
            ``joints``, the robot, the kinds held, and those the moving joints have finite
            limits of, among ``served``).
    """
    found = unbounded_stretch(constraints)
    if found is None:
        return
    first, last = found
    middle = (first + last) // 2
    moving = np.flatnonzero(np.abs(path.evaluate(constraints.s[middle : middle + 1]).dq[0]) > 1e-12)
    joints = tuple(robot.joint_names[j] for j in moving)
    s_from, s_to = float(s_of(constraints.s[first])), float(s_of(constraints.s[last]))
    raise InvalidRequest(
        field, list(kinds), rule="stretch_unbounded", robot=robot.name, kinds=tuple(kinds), s=s_from, s_from=s_from, s_to=s_to,
        joints=joints, available=_available(limits, served, moving),
        detail=f"from s = {s_from:.4f} to {s_to:.4f} no limit held bounds the motion of {', '.join(joints) or 'the tool'}",
    )
