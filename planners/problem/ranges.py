"""Accepted ranges of the physical numbers a request carries (SI units).

The planners raise speeds to the second and third power and divide by the fifth power of a
duration (a quintic's coefficients), so numbers far outside what any arm does overflow to inf or
underflow to zero and no longer describe a motion: a duration of 1e-300 s, a boundary speed of
1e300 rad/s or a switching fraction of 5e-324 turned into infinite samples and singular
systems. Every such number is held to a range here, the service declares the same ranges in its
schema (OpenAPI ``minimum``/``maximum``), and ``plan`` checks them for library callers.

A ``Range`` bounds a magnitude: positive quantities (limits, durations, scale factors) lie in
[low, high]; signed ones (boundary velocities and accelerations) in [-high, high].
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.errors import InvalidRequest, OutOfRange
from toptraj.robots.ranges import ACCELERATION as ACCELERATION
from toptraj.robots.ranges import JERK as JERK
from toptraj.robots.ranges import LIMITS as LIMITS
from toptraj.robots.ranges import TORQUE as TORQUE
from toptraj.robots.ranges import VELOCITY as VELOCITY
from toptraj.robots.ranges import Range as Range

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from toptraj.planners.problem.problem import BoundaryStates, LimitRequest
    from toptraj.robots import JointLimits

#: Joint coordinates (rad or m): a continuous joint may turn many times, not 1e300.
COORDINATE = Range(0.0, 1e4, "rad or m")
#: Duration of a time law or of the via-point motion (s).
DURATION = Range(1e-3, 1e4, "s")
#: Sample period of the returned trajectory (s): 1 MHz is faster than any drive's loop.
DT = Range(1e-6, 10.0, "s")
#: Per-joint limit overrides and the magnitude of boundary states (rad or m, per s^k) lie in
#: the ranges of the robots' own limits: ``toptraj.robots.ranges`` VELOCITY, ACCELERATION, JERK, TORQUE.

#: Tool-speed limits (m/s, rad/s).
TOOL_SPEED = Range(1e-6, 1e3, "m/s")
TOOL_ANGULAR_SPEED = Range(1e-6, 1e3, "rad/s")
#: Largest distance of a blended corner from its waypoint (joint-space norm, rad or m).
MAX_DEVIATION = Range(1e-9, 1e4, "rad or m")
#: Spacing below which a waypoint repeats its neighbour, as a share of the path's joint-space
#: length (beyond a hundredth it would resample the path, not merge repeats).
MIN_SPACING = Range(0.0, 1e-2, "")
#: Factors on a robot's limits.
SCALE = Range(1e-3, 1e3, "")
#: Switching fractions of the trapezoidal law (acceleration ends at tau1, cruise at tau2).
TRAPEZOID_FRACTION = Range(1e-3, 1.0 - 1e-3, "")


def check(value: float, field: str, accepted: Range) -> None:
    """OutOfRange (the library's ``field``) unless ``value`` lies in ``accepted``."""
    if not (isinstance(value, (int, float)) and math.isfinite(value) and accepted.holds(value)):
        raise OutOfRange(field, value, accepted.low, accepted.high, accepted.unit)


def check_vector(values: ArrayLike, field: str, accepted: Range, signed: bool = False) -> None:
    """OutOfRange (``field[i]``) unless every entry of ``values`` lies in ``accepted`` (by
    magnitude, and any sign, when ``signed``: [-high, high])."""
    try:
        array = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InvalidRequest(field, values, rule="not_numbers") from None
    inside = (np.abs(array) <= accepted.high) if signed else ((array >= accepted.low) & (array <= accepted.high))
    bad = np.flatnonzero(~inside)
    if bad.size:
        low = -accepted.high if signed else accepted.low
        raise OutOfRange(f"{field}[{bad[0]}]", array[bad[0]], low, accepted.high, accepted.unit, signed=signed)


def check_numbers(limits: LimitRequest, boundary: BoundaryStates, duration: float | None, dt: float) -> None:
    """Hold every number of a problem's ``LimitRequest`` and ``BoundaryStates``
    (``toptraj.planners.problem.problem``), its ``duration`` and the sample period ``dt`` to its
    range (OutOfRange naming the field and the range otherwise)."""
    check(dt, "sampling.dt", DT)
    if duration is not None:
        check(duration, "duration", DURATION)
    for kind, values in (limits.overrides or {}).items():
        if values is not None and kind in LIMITS:
            check_vector(values, f"limits.{kind}", LIMITS[kind])
    for name, accepted in (("tool_speed", TOOL_SPEED), ("tool_angular_speed", TOOL_ANGULAR_SPEED)):
        value = getattr(limits, name, None)
        if value is not None:
            check(value, f"limits.{name}", accepted)
    for kind, factor in (limits.scales or {}).items():
        if factor is not None:
            check(factor, f"limits.{kind}_scale", SCALE)
    for name, accepted in (
        ("start_velocity", VELOCITY),
        ("end_velocity", VELOCITY),
        ("start_acceleration", ACCELERATION),
        ("end_acceleration", ACCELERATION),
    ):
        values = getattr(boundary, name)
        if values is not None:
            check_vector(values, f"boundary.{name}", accepted, signed=True)


def _round_inward(low: float, high: float) -> tuple[float, float]:
    """[low, high] with each end rounded to 3 significant digits, inward (so that advice shown
    with ``:g`` lies inside the interval)."""

    def rounded(value: float, up: bool) -> float:
        if value <= 0.0 or not math.isfinite(value):
            return value
        step = 10.0 ** (math.floor(math.log10(value)) - 2)
        return (math.ceil if up else math.floor)(value / step - (1e-9 if up else -1e-9)) * step

    return rounded(low, True), rounded(high, False)


def check_scaled_limits(limits: JointLimits, scales: dict[str, float | None] | None, joint_names: tuple[str, ...]) -> None:
    """InvalidRequest unless every finite limit of ``limits`` (a ``JointLimits`` with the
    request's overrides, before its scales) times its ``scales`` factor lies in the range of its
    kind: a scale is one more source of a limit, and outside the range a limit (1e-9 rad/s^3 from
    jerk_scale 1e-3 on 1e-6) is one the methods are not known to plan with. The message names
    the joint, the scaled limit and the factors that keep every joint's limit in its range."""
    for kind, factor in (scales or {}).items():
        if factor is None or kind not in LIMITS:
            continue
        values = np.asarray(getattr(limits, kind), dtype=float)
        finite = np.isfinite(values)
        if not finite.any():
            continue
        accepted = LIMITS[kind]
        scaled = values * factor
        outside = np.flatnonzero(finite & ~((scaled >= accepted.low) & (scaled <= accepted.high)))
        if outside.size == 0:
            continue
        joint = int(outside[0])
        name = joint_names[joint] if joint < len(joint_names) else str(joint)
        low, high = _round_inward(
            max(SCALE.low, accepted.low / float(values[finite].min())),
            min(SCALE.high, accepted.high / float(values[finite].max())),
        )
        raise OutOfRange(
            f"limits.{kind}_scale", factor, accepted.low, accepted.high, accepted.unit, rule="scaled_limit_out_of_range",
            kind=kind, joint_name=name, scaled=float(scaled[joint]), advised=(low, high) if low <= high else None,
        )
