"""The remedy of a path that cannot be held still within the torque limits
(``toptraj.planners.constraints.held_load.not_even_at_rest``), in the limits as asked.

Where holding still needs ``ratio`` times the torque limit in force (the limit as asked, times
its scale and ``1 - margin``), a torque scale ``ratio`` times the one asked, or a limit
``ratio`` times the one asked on that joint, holds it. With every joint able to hold the path
everywhere, with room to spare, a slow enough motion follows the path: its inertial and
velocity terms vanish with the path speed (Bobrow, Dubowsky & Gibson 1985, the phase plane at
sd -> 0).

Inside a zone that scales the torque limits down (``timing.zones``), holding still may exceed
only the zone's limits: where the limits outside the zones would hold the path still at every
point (each point's share of its limits in force times the zone factor there at most 1), the
remedy is the zones' own torque scales (``zone_remedy``), not the limits of the whole path,
which would raise them outside the zones as well.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.held_load import rest_loads
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.constraints.zones import inside, with_edges, zone_factors
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.problem import Problem
from toptraj.planners.problem.ranges import SCALE
from toptraj.planners.runner.duration import rounded_up
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
    asked = problem.requested
    scale = asked.scales.get("torque") or 1.0
    zoned = facts.pop("zone_scales", ())
    if zoned:
        facts.update(asked_scale=scale, torque_scale=None, torque_limits=(), zone_scales=zoned)
        return type(error)(error.detail, **facts)
    limits = np.asarray(problem.robot.limits.with_request(asked.overrides).torque, dtype=float)
    names = problem.robot.joint_names
    needed, beyond = [], []
    for ratio, load in facts["joints"]:
        if not (np.isfinite(ratio) and np.isfinite(limits[names.index(load.joint)])):
            continue
        value = rounded_up(float(limits[names.index(load.joint)]) * ratio * (1.0 + ROOM), ADVISED_DIGITS)
        in_force = rounded_up(float(limits[names.index(load.joint)]) * scale * ratio * (1.0 + ROOM), ADVISED_DIGITS)
        if not (np.isfinite(in_force) and in_force <= TORQUE.high):
            beyond.append((load.joint, in_force, load.unit))
        needed.append((load.joint, value, in_force, load.unit))
    if beyond:  # no limit accepted holds that joint: advice for the others would not plan the path
        facts.update(asked_scale=scale, torque_scale=None, torque_limits=(), beyond_range=tuple(beyond), most=TORQUE.high)
        return type(error)(error.detail, **facts)
    if all(TORQUE.low <= value <= TORQUE.high for _, value, _, _ in needed):  # overrides under the scale asked
        limits_advised = tuple((joint, value, unit) for joint, value, _, unit in needed)
        unscaled = False
    else:  # an override beyond the range under the scale: the limits in force, without the scale
        limits_advised = tuple((joint, in_force, unit) for joint, _, in_force, unit in needed)
        unscaled = True
    advised = rounded_up(scale * facts["ratio"] * (1.0 + ROOM), ADVISED_DIGITS) if np.isfinite(facts["ratio"]) else None
    finite = limits[np.isfinite(limits)]
    if not (advised is not None and SCALE.low <= advised <= SCALE.high and (finite * advised <= TORQUE.high).all()):
        advised = None
    facts.update(asked_scale=scale, torque_scale=advised, torque_limits=limits_advised, without_scale=unscaled)
    return type(error)(error.detail, **facts)


def zone_remedy(problem: Problem, path: GeometricPath) -> tuple[tuple[int, float], ...]:
    """(zone index, torque scale) for the zones of ``problem`` (located on ``path``) whose torque
    scales alone keep the path from being held still, when raising them holds it everywhere
    (module docstring); empty otherwise. Holding still is measured on the path's default grid
    (``rest_loads``: each point's largest share of a joint's limit in force there), and a zone
    is raised to the largest share its own points need without the zones' factors (the grid holds
    each zone's edges, so that a zone narrower than a grid interval has points of its own)."""
    zones = tuple(zone for zone in problem.limits.zones if zone.torque < 1.0)
    if not zones:
        return ()
    grid = with_edges(path_grid(path), problem.limits.zones, np.asarray(path.knots, dtype=float))  # each zone's edges on it
    constraints = build_path_constraints(path, problem.robot, problem.limits, ("torque",), grid, problem.deadline)
    ratios, _ = rest_loads(constraints)
    if not ratios.size:
        return ()
    factor = zone_factors(zones, constraints.s).torque
    unzoned = ratios.max(axis=1) * factor  # each point's share of the limits outside the zones
    if not (np.isfinite(unzoned).all() and unzoned.max() <= 1.0):
        return ()  # the limits outside the zones do not hold it either
    needed = {}
    for zone in zones:
        within = inside(zone, constraints.s)
        if within.any() and unzoned[within].max() > zone.torque:
            needed[zone.index] = min(1.0, rounded_up(float(unzoned[within].max()) * (1.0 + ROOM), ADVISED_DIGITS))
    return tuple(sorted(needed.items()))
