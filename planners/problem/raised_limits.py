"""Limits asked far above the robot's own: a note in the answer, for a value given in degrees
(57 times the radians), a scale given in percent (100 times the factor) or a torque override
for the wrong joint would otherwise be planned under without a word, and the answer's
utilizations, measured against the limits asked, would not show it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj.robots.chain import sliding_joints
from toptraj.robots.notes import Note
from toptraj.robots.ranges import LIMITS

if TYPE_CHECKING:
    from toptraj.planners.problem.problem import LimitRequest
    from toptraj.robots import Robot

#: A limit asked above this many times the robot's own is noted (the robot's limits are the
#: rated ones of its URDF, joint_limits.yaml or catalog entry; 3 leaves room for conservative
#: ratings).
RAISED_FACTOR = 3.0
#: The units of a prismatic joint's limits (a revolute joint's: ``LIMITS[kind].unit``).
PRISMATIC_UNITS = {"velocity": "m/s", "acceleration": "m/s^2", "jerk": "m/s^3", "torque": "N"}


def raised_limits(robot: Robot, asked: LimitRequest, kinds: tuple[str, ...]) -> tuple[Note, ...]:
    """A note per limit kind whose overrides or scale in ``asked`` put some joint's limit above
    ``RAISED_FACTOR`` times the robot's own rated one (finite, and not from the service's
    default rule): the joint that is raised most, its limit asked and its own (SI units), the
    override and the scale that raised it, and whether the kind is held (``kinds``; one that
    is not is still reported against it in ``peak_utilization``)."""
    notes = []
    for kind in LIMITS:
        override, scale = asked.overrides.get(kind), asked.scales.get(kind)
        if override is None and scale is None:
            continue
        own = np.asarray(getattr(robot.limits, kind), dtype=float)
        held = (own if override is None else np.asarray(override, dtype=float)) * (1.0 if scale is None else scale)
        sources = robot.limit_sources.get(kind, ())
        rated = np.isfinite(own) & (own > 0.0) & np.array([not str(source).startswith("default") for source in sources] or [True] * robot.dof)
        ratio = np.where(rated, held / np.where(rated, own, 1.0), 0.0)
        joint = int(np.argmax(ratio))
        if not ratio[joint] > RAISED_FACTOR:
            continue
        prismatic = bool(sliding_joints(robot.model)[joint])
        unit = PRISMATIC_UNITS[kind] if prismatic else LIMITS[kind].unit
        given = None if override is None else float(override[joint])
        field = f"limits.{kind}[{joint}]" if override is not None else f"limits.{kind}_scale"
        notes.append(Note(
            f"{field} puts the {kind} limit of joint {robot.joint_names[joint]!r} at {held[joint]:.4g} {unit}, "
            f"{ratio[joint]:.3g} times its own ({own[joint]:.4g})",
            "limit_far_above_own", field=field, kind=kind, override=given, scale=scale, held=kind in kinds,
            index=joint, joint_name=robot.joint_names[joint], value=float(held[joint]), own=float(own[joint]), ratio=float(ratio[joint]),
            unit=unit, prismatic=prismatic,
        ))
    return tuple(notes)
