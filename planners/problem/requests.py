"""What a caller asks of ``plan`` about the path: joint waypoints (Cartesian lines and free
motions live with their planners), and the limit kinds a method is asked to respect."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.constraints.path_constraints import CONSTRAINT_KINDS
from toptraj.planners.errors import InvalidRequest, NotOneOf, NotServed
from toptraj.planners.timing.base import TimingMethod

if TYPE_CHECKING:
    from toptraj.planners.problem.methods import MotionGenerator

#: Largest distance of a blend from its waypoint when a request names none (joint units): the
#: default path tolerance of MoveIt's time-optimal trajectory generation.
DEFAULT_MAX_DEVIATION = 0.1
#: Default ``min_spacing``: a waypoint nearer its kept neighbour than this share of the path's
#: joint-space length is a repeat. Grid timings (toppra, min_cost) fail on a spline through a
#: waypoint 1e-5 of the path's length from another (the Geering arm, seeded trials; the bend's
#: sharpness, about 1 / spacing, outruns the grid's conditioning); at 1e-4 they answered.
DEFAULT_MIN_SPACING = 1e-4
#: Limit kinds respected when a caller names none (those of them the method holds).
DEFAULT_KINDS = ("velocity", "acceleration", "torque")


@dataclass(frozen=True)
class WaypointPath:
    """A joint path through ``waypoints`` (shape (n_waypoints, n_dof), joint units), interpolated
    by ``"spline"`` (C2 cubic), ``"linear"`` (straight segments, stopping at each waypoint),
    ``"blend"`` (straight segments joined by circular blends within ``max_deviation`` of each
    waypoint, joint-space norm in joint units; default ``DEFAULT_MAX_DEVIATION``) or ``"via"``
    (per-joint cubic or quintic segments in time through the via points, the law named by the
    timing method). Continuous joints (no position limits) follow the numbers given
    (``continuous = "as_given"``) or turn the short way between waypoints (``"shortest"``).
    A waypoint within ``min_spacing`` times the path's joint-space length of the waypoint kept
    before it is dropped as a repeat (a waypoint so near the last, in the last's place);
    ``None``: ``DEFAULT_MIN_SPACING`` on a spline or blend, 0 otherwise. ``origin``: the
    index as given of each waypoint, once repeats are dropped (``None``: as given)."""

    waypoints: np.ndarray
    interpolation: str = "spline"
    max_deviation: float | None = None
    continuous: str = "as_given"
    min_spacing: float | None = None
    origin: tuple[int, ...] | None = None


def default_kinds(method: TimingMethod | MotionGenerator) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(kinds, unheld): the ``DEFAULT_KINDS`` that ``method`` holds, and those it cannot hold
    (left out, for the answer to tell)."""
    held = tuple(kind for kind in DEFAULT_KINDS if kind in method.kinds)
    return held, tuple(kind for kind in DEFAULT_KINDS if kind not in method.kinds)


def check_constraint_kinds(kinds: Iterable[str], method: TimingMethod | MotionGenerator) -> tuple[str, ...]:
    """``kinds`` checked (each a known constraint kind that ``method`` serves), with the kinds
    ``method`` requires added, in order and without repeats."""
    unknown = [kind for kind in kinds if kind not in CONSTRAINT_KINDS]
    if unknown:
        raise NotOneOf("constraints", unknown[0], CONSTRAINT_KINDS, rule="unknown_constraint")
    unsupported = [kind for kind in kinds if kind not in method.kinds]
    if unsupported:
        raise NotServed(
            "constraints", unsupported[0], method.name, rule="kind_not_served", handles=sorted(method.kinds),
            kept=tuple(kind for kind in dict.fromkeys(kinds) if kind in method.kinds),
        )
    kinds = tuple(dict.fromkeys([*kinds, *sorted(method.required_kinds)]))
    if not kinds:
        raise InvalidRequest("constraints", kinds, rule="no_constraints")
    return kinds
