"""A refusal that holding still explains, on a path timed stretch by stretch (between corners,
``toptraj.planners.paths.stretch``): its places in the whole path's s, and the loads at rest of
every stretch, so that the remedy (``toptraj.planners.runner.holding``) holds the whole path."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.constraints.held_load import HeldLoad, RestExcess, holding_excesses
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.constraints.zones import on_stretch
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.paths.stretch import Stretch

if TYPE_CHECKING:
    from toptraj.planners.execution.deadline import Deadline
    from toptraj.robots import JointLimits, Robot


def over_every_stretch(
    error: InfeasiblePath, failed: Stretch, parts: list[tuple[object, np.ndarray]], robot: Robot, limits: JointLimits,
    kinds: tuple[str, ...], deadline: Deadline,
) -> InfeasiblePath:
    """``error`` of the stretch ``failed`` with its places (``s``, the ``held`` load, the
    ``stretches`` and ``ends`` of ``not_even_at_rest``) in the whole path's s, and its
    ``joints`` (each joint's largest share of its limit at rest, ``ratio`` the largest) taken
    over every stretch of ``parts`` ((stretch, its grid) each; one RNEA per grid point)."""
    def parent(s: float) -> float:
        return float(failed.to_parent(np.atleast_1d(s))[0])

    def moved(load: HeldLoad) -> HeldLoad:
        return load._replace(s=parent(load.s))

    worst: dict[str, tuple[float, HeldLoad]] = {}
    for part, grid in parts:
        assert isinstance(part, Stretch)  # a path with corners comes apart into stretches
        deadline.check()
        constraints = build_path_constraints(part, robot, on_stretch(limits, part.start, part.width), kinds, grid, deadline)
        for ratio, load in holding_excesses(constraints):
            load = load._replace(s=float(part.to_parent(np.atleast_1d(load.s))[0]))
            if ratio > worst.get(load.joint, (0.0, load))[0]:
                worst[load.joint] = (ratio, load)
    facts = {key: value for key, value in vars(error).items() if key != "detail"}
    if facts.get("s") is not None:
        facts["s"] = parent(facts["s"])
    if facts.get("held") is not None:
        facts["held"] = moved(facts["held"])
    if "stretches" in facts:
        facts["stretches"] = tuple(
            RestExcess(parent(item.start), parent(item.end), moved(item.worst)) for item in facts["stretches"]
        )
    if "ends" in facts:
        facts["ends"] = tuple(moved(load) for load in facts["ends"])
    if worst:
        facts["joints"] = tuple(worst.values())
        facts["ratio"] = max(ratio for ratio, _ in worst.values())
    return type(error)(error.detail, **facts)
