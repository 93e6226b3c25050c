"""What a caller asks of ``plan``: the path (joint waypoints; Cartesian lines and free motions
live with their planners) and the timing, and the timing method that a request names."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from toptraj.planners.constraints.path_constraints import CONSTRAINT_KINDS
from toptraj.planners.errors import Conflicting, InvalidRequest, NotOneOf, NotServed, OutOfRange
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.problem.zones import Zone
from toptraj.planners.timing import METHODS
from toptraj.planners.timing.base import TimingMethod
from toptraj.planners.timing.laws.method import ClassicalMethod
from toptraj.planners.timing.laws.profiles import PROFILES, CycloidalBlendProfile, NormalizedProfile, TrapezoidalProfile
from toptraj.planners.timing.laws.splines import MAX_SUPPORTING_POINTS, MIN_SUPPORTING_POINTS, SplineProfile

if TYPE_CHECKING:
    from toptraj.planners.problem.methods import MotionGenerator

#: Largest distance of a blend from its waypoint when a request names none (joint units): the
#: default path tolerance of MoveIt's time-optimal trajectory generation.
DEFAULT_MAX_DEVIATION = 0.1


@dataclass(frozen=True)
class WaypointPath:
    """A joint path through ``waypoints`` (shape (n_waypoints, n_dof), joint units), interpolated
    by ``"spline"`` (C2 cubic), ``"linear"`` (straight segments, stopping at each waypoint),
    ``"blend"`` (straight segments joined by circular blends within ``max_deviation`` of each
    waypoint, joint-space norm in joint units; default ``DEFAULT_MAX_DEVIATION``) or ``"via"``
    (per-joint cubic or quintic segments in time through the via points, the law named by the
    timing method). Continuous joints (no position limits) follow the numbers given
    (``continuous = "as_given"``) or turn the short way between waypoints (``"shortest"``)."""

    waypoints: np.ndarray
    interpolation: str = "spline"
    max_deviation: float | None = None
    continuous: str = "as_given"


@dataclass(frozen=True)
class Timing:
    """How to time the path.

    Attributes:
        method: A ``timing.method`` name (see ``toptraj.planners.timing.METHODS``).
        constraints: Which limits to respect, among velocity, acceleration and torque.
        limit_overrides: Per-joint replacements, keys ``velocity``, ``acceleration``, ``jerk``,
            ``torque``.
        limit_scales: Factors on those limits, same keys.
        grid_points: Number of grid intervals; ``None`` chooses one from the path.
        start_velocity, end_velocity: Joint velocities at the ends (rad/s), tangent to the path;
            ``None`` is rest.
        start_acceleration, end_acceleration: Joint accelerations at the ends (rad/s^2), for the
            laws that take them (quintic).
        duration: Seconds, for the time laws; ``None`` asks for the shortest within the limits.
        trapezoid_fractions: (tau1, tau2), the trapezoidal law's ends of acceleration and of
            cruise as fractions of the duration.
        trapezoid_blend: ``"linear"`` (constant acceleration, Angeles 6.1) or ``"cycloidal"``
            (cycloidal blends, Angeles 6.3) for the trapezoidal law's speed ramps.
        supporting_points: For a time law, approximate it by the cubic spline through this many
            equally spaced points of it (Angeles 6.1 (c), ``toptraj.planners.timing.laws.splines``);
            ``None``: the law itself.
        synchronization: For a time law on a straight joint move (two waypoints):
            ``"normalized"`` times the straight joint line as one, every joint starting and
            stopping together; ``"none"`` runs every joint at its own full speed to its goal
            (lecture "Trajectory Planning"; ``toptraj.planners.generators.unsynchronized``).
        torque_weight: beta of the cost integral of (1 + beta |tau|^2) dt, in 1/(N m)^2, for
            ``min_cost``.
        limit_margin: Fraction of every velocity, acceleration, jerk, torque and tool-speed
            limit kept in reserve (0 to 0.5): the timing is planned under the limits times
            (1 - margin), and with a positive margin no returned state exceeds the limits
            themselves.
        tool_speed: Largest linear speed of the tool frame's origin, m/s; ``None``: none.
        tool_angular_speed: Largest angular speed of the tool frame, rad/s; ``None``: none.
        tool_frame: The frame those speeds limit; ``None``: the robot's end effector.
        search: Options of the global search (``timing.method = "search"``); ``None``: the
            defaults of ``toptraj.planners.generators.search.SearchOptions``.
        zones: Limits of their own on parts of the path (``toptraj.planners.problem.zones.Zone``),
            at most ``MAX_ZONES``; the robot's hold elsewhere.
    """

    method: str = "phase_plane"
    constraints: tuple[str, ...] = ("velocity", "acceleration", "torque")
    limit_overrides: dict[str, list[float] | None] = field(default_factory=dict)
    limit_scales: dict[str, float | None] = field(default_factory=dict)
    grid_points: int | None = None
    start_velocity: ArrayLike | None = None
    end_velocity: ArrayLike | None = None
    start_acceleration: ArrayLike | None = None
    end_acceleration: ArrayLike | None = None
    duration: float | None = None
    trapezoid_fractions: tuple[float, float] = (1.0 / 3.0, 2.0 / 3.0)
    trapezoid_blend: str = "linear"
    supporting_points: int | None = None
    synchronization: str = "normalized"
    torque_weight: float = 0.0
    limit_margin: float = 0.0
    tool_speed: float | None = None
    tool_angular_speed: float | None = None
    tool_frame: str | None = None
    search: SearchOptions | None = None
    zones: tuple[Zone, ...] = ()


def check_constraint_kinds(kinds, method: TimingMethod | MotionGenerator) -> tuple[str, ...]:
    unknown = [kind for kind in kinds if kind not in CONSTRAINT_KINDS]
    if unknown:
        raise NotOneOf("constraints", unknown[0], CONSTRAINT_KINDS, rule="unknown_constraint")
    unsupported = [kind for kind in kinds if kind not in method.kinds]
    if unsupported:
        raise NotServed("constraints", unsupported[0], method.name, rule="kind_not_served", handles=sorted(method.kinds))
    kinds = tuple(dict.fromkeys([*kinds, *sorted(method.required_kinds)]))
    if not kinds:
        raise InvalidRequest("constraints", kinds, rule="no_constraints")
    return kinds


#: Trapezoid ramps by ``timing.trapezoid.blend``.
BLENDS: dict[str, type[TrapezoidalProfile]] = {"linear": TrapezoidalProfile, "cycloidal": CycloidalBlendProfile}
SYNCHRONIZATIONS = ("normalized", "none")
#: Method names of the motion generators that find a free path themselves.
GENERATORS = ("collocation", "search")


def law_profile(timing: Timing) -> NormalizedProfile:
    """The normalized profile of a time law request: the law (trapezoid fractions and blend),
    or its spline through ``timing.supporting_points`` points."""
    profile: NormalizedProfile
    if timing.method == "trapezoidal":
        tau1, tau2 = timing.trapezoid_fractions
        if not (np.isfinite(tau1) and np.isfinite(tau2) and 0.0 < tau1 <= tau2 < 1.0):
            raise InvalidRequest("law.trapezoid", (tau1, tau2), rule="trapezoid_order")
        if timing.trapezoid_blend not in BLENDS:
            raise NotOneOf("law.blend", timing.trapezoid_blend, list(BLENDS))
        profile = BLENDS[timing.trapezoid_blend](tau1, tau2)
    else:
        profile = PROFILES[timing.method]()
    if timing.supporting_points is None:
        return profile
    points = timing.supporting_points
    if not (isinstance(points, int) and MIN_SUPPORTING_POINTS <= points <= MAX_SUPPORTING_POINTS):
        raise OutOfRange("law.supporting_points", points, MIN_SUPPORTING_POINTS, MAX_SUPPORTING_POINTS, rule="count_out_of_range")
    try:
        return SplineProfile(profile, points)
    except ValueError as error:
        raise InvalidRequest("law.supporting_points", points, rule="law_spline_failed", reason=str(error)) from None


def _check_law_options(timing: Timing) -> None:
    """Refuse the time-law options with a method that does not use them."""
    law = timing.method in PROFILES
    if timing.trapezoid_blend != "linear" and timing.method != "trapezoidal":
        raise NotServed("law.blend", timing.trapezoid_blend, timing.method, rule="blend_needs_trapezoidal", alternatives=("trapezoidal",))
    if timing.supporting_points is not None and not law:
        raise NotServed("law.supporting_points", timing.supporting_points, timing.method, rule="needs_time_law",
                        alternatives=tuple(PROFILES))
    moving = [value for value in (timing.start_velocity, timing.end_velocity, timing.start_acceleration, timing.end_acceleration)
              if value is not None and np.any(np.asarray(value) != 0.0)]
    if timing.supporting_points is not None and moving:
        raise Conflicting("law.supporting_points", timing.supporting_points, ("boundary",), rule="law_from_rest")
    if timing.synchronization not in SYNCHRONIZATIONS:
        raise NotOneOf("law.synchronization", timing.synchronization, SYNCHRONIZATIONS)
    if timing.synchronization == "none" and not law:
        raise NotServed("law.synchronization", timing.synchronization, timing.method, rule="unsynchronized_needs_law",
                        alternatives=tuple(PROFILES))


def timing_method(timing: Timing) -> TimingMethod | None:
    """The timing method named by ``timing.method`` (with its per-request options), after the
    checks of the options every method shares; ``None`` for the names of motion generators
    (``collocation``, ``search``), which the caller builds."""
    _check_law_options(timing)
    if timing.method == "trapezoidal" or (timing.method in PROFILES and timing.supporting_points is not None):
        method = METHODS[timing.method]
        boundary_law = getattr(method, "boundary_law", None) if timing.supporting_points is None else None
        return ClassicalMethod(law_profile(timing), boundary_law=boundary_law)
    if timing.torque_weight != 0.0 and timing.method not in ("min_cost", "collocation"):
        raise NotServed("method.torque_weight", timing.torque_weight, timing.method, rule="weight_needs_min_cost",
                        alternatives=("min_cost",))
    if timing.method == "min_cost":
        if not (np.isfinite(timing.torque_weight) and timing.torque_weight >= 0.0):
            raise OutOfRange("method.torque_weight", timing.torque_weight, 0.0, float("inf"), "1/(N m)^2", rule="negative_weight")
        from toptraj.planners.timing.min_cost import MinCostMethod  # here: the other methods do without it

        return MinCostMethod(timing.torque_weight)
    if timing.method in GENERATORS:
        return None
    if timing.search is not None:
        raise NotServed("search", None, timing.method, rule="options_need_search", alternatives=("search",))
    named = METHODS.get(timing.method)
    if named is None:
        raise NotOneOf("method", timing.method, sorted([*METHODS, "collocation", "search"]))
    return named
