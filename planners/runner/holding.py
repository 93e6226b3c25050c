"""The remedy of a path that cannot be held still within the torque limits
(``toptraj.planners.constraints.held_load.not_even_at_rest``), in the limits as asked.

Where holding still needs ``ratio`` times the torque limit in force (the limit as asked, times
its scale and ``1 - margin``), a torque scale ``ratio`` times the one asked, or a limit
``ratio`` times the one asked on that joint, holds it. With every joint able to hold the path
everywhere, with room to spare, a slow enough motion follows the path: its inertial and
velocity terms vanish with the path speed (Bobrow, Dubowsky & Gibson 1985, the phase plane at
sd -> 0).

Inside a zone that scales the torque limits down (``timing.zones``), holding still may exceed
only the zone's limits: where every joint's worst load would be held by the limits outside the
zones (its ratio times the zone's factor at most 1), the remedy is the zones' own torque scales
(the factor times the ratio), not the limits of the whole path, which would raise them outside
the zones as well.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.zones import inside, zone_factors
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.problem.problem import Problem
from toptraj.planners.problem.ranges import SCALE
from toptraj.planners.runner.duration import rounded_up
from toptraj.robots import LimitZone
from toptraj.robots.ranges import TORQUE

#: Significant digits of the torque scale and limits advised (rounded up: room to spare).
ADVISED_DIGITS = 3
#: Room the advice keeps above the torque that holding needs (a fraction of it).
ROOM = 1e-3


def with_torque_remedy(problem: Problem, error: InfeasiblePath) -> InfeasiblePath:
    """``error`` (one that holding still beyond a torque limit explains: its facts ``joints``
    and ``ratio``, ``toptraj.planners.constraints.held_load.holding_facts``) with the torque scale and the per-joint torque
    limits, as ``problem`` asks for them, that hold the path still everywhere: facts
    ``asked_scale`` (the torque scale asked, 1 without one), ``torque_scale`` (it times the
    largest ratio, rounded up; ``None`` outside the accepted ranges) and ``torque_limits``
    ((joint, value, unit: N m or N) for each joint beyond its limit: its limit as asked, before
    the scale, times its ratio, rounded up, where that lies in the accepted range). Where a
    joint would need a limit beyond the accepted range, no limit advice holds the path:
    ``beyond_range`` ((joint, value, unit) for each such joint) and ``most`` (the range's top)
    instead."""
    facts = {key: value for key, value in vars(error).items() if key != "detail"}
    zoned = _zone_remedy(facts.pop("zones", problem.limits.zones), facts["joints"])
    if zoned:
        facts.update(asked_scale=problem.requested.scales.get("torque") or 1.0, torque_scale=None, torque_limits=(), zone_scales=zoned)
        return type(error)(error.detail, **facts)
    asked = problem.requested
    scale = asked.scales.get("torque") or 1.0
    limits = np.asarray(problem.robot.limits.with_request(asked.overrides).torque, dtype=float)
    names = problem.robot.joint_names
    needed, beyond = [], []
    for ratio, load in facts["joints"]:
        if not (np.isfinite(ratio) and np.isfinite(limits[names.index(load.joint)])):
            continue
        value = rounded_up(float(limits[names.index(load.joint)]) * ratio * (1.0 + ROOM), ADVISED_DIGITS)
        if np.isfinite(value) and TORQUE.low <= value * scale <= TORQUE.high and value <= TORQUE.high:
            needed.append((load.joint, value, load.unit))
        else:
            beyond.append((load.joint, value * scale, load.unit))
    if beyond:  # no limit accepted holds that joint: advice for the others would not plan the path
        facts.update(asked_scale=scale, torque_scale=None, torque_limits=(), beyond_range=tuple(beyond), most=TORQUE.high)
        return type(error)(error.detail, **facts)
    advised = rounded_up(scale * facts["ratio"] * (1.0 + ROOM), ADVISED_DIGITS) if np.isfinite(facts["ratio"]) else None
    finite = limits[np.isfinite(limits)]
    if not (advised is not None and SCALE.low <= advised <= SCALE.high and (finite * advised <= TORQUE.high).all()):
        advised = None
    facts.update(asked_scale=scale, torque_scale=advised, torque_limits=tuple(needed))
    return type(error)(error.detail, **facts)


def _zone_remedy(located: tuple[LimitZone, ...], joints: tuple) -> tuple[tuple[int, float], ...]:
    """(zone index, torque scale) for each of the zones ``located`` on the path that alone keeps
    a joint from holding it still (module docstring), when the zones alone do; empty otherwise."""
    zones = tuple(zone for zone in located if zone.torque < 1.0)
    if not zones or not joints:
        return ()
    needed: dict[int, float] = {}
    for ratio, load in joints:
        at = np.array([load.s])
        factor = float(zone_factors(zones, at).torque[0])
        if not np.isfinite(ratio) or ratio * factor > 1.0:
            return ()  # the limits outside the zones do not hold it either
        for zone in zones:
            if factor < 1.0 and zone.torque == factor and inside(zone, at)[0]:
                value = min(1.0, rounded_up(ratio * factor * (1.0 + ROOM), ADVISED_DIGITS))
                needed[zone.index] = max(needed.get(zone.index, 0.0), value)
    return tuple(sorted(needed.items()))
