"""The exact jerk-limited optimum where every limit is the same along the whole path: the
double-S (seven-segment) profile of the path parameter, in closed form.

On a path whose limits do not change along it (a straight joint line under velocity,
acceleration and jerk limits, ``toptraj.planners.timing.jerk.method._uniform``) every row reduces to a
bound on the path parameter alone,

    |sd| <= V = min_k v_k / |q'_k|,   |sdd| <= A = min_k a_k / |q'_k|,
    |sddd| <= J = min_k j_k / |q'_k|,

and the time-optimal motion from rest at s = 0 to rest at s = 1 is the double-S profile
(Biagiotti & Melchiorri, "Trajectory Planning for Automatic Machines and Robots", Springer 2008,
§3.4, eqs. (3.30)-(3.33) for the case q0 -> q1 = q0 + h with v0 = v1 = 0): with Tj the time of
each ramp of the acceleration, Ta the time of each acceleration phase and Tv the cruise,

* V reached (h >= V Ta): Tj = A / J and Ta = Tj + V / A when V J >= A^2, else Tj = sqrt(V / J)
  and Ta = 2 Tj (A not reached); Tv = h / V - Ta, so T = h / V + Ta (= h/V + V/A + A/J when
  both limits are reached);
* V not reached, A reached (h >= 2 A^3 / J^2): Tj = A / J, Ta = (Tj + sqrt(Tj^2 + 4 h / A)) / 2,
  Tv = 0;
* neither: Tj = (h / (2 J))^(1/3), Ta = 2 Tj, Tv = 0.

The motion is returned as its seven segments of constant path jerk (``JerkSegmentsTiming``),
segments of zero duration left out.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.timing.jerk.segments import JerkSegmentsTiming

#: Relative size below which a coefficient that would make a row depend on the speed (q'' and
#: q''' of a straight line, friction) counts as rounding noise.
NOISE = 1e-9
#: Relative asymmetry of the acceleration bounds below which they count as symmetric.
SYMMETRY = 1e-12


class ScalarLimits(NamedTuple):
    """Bounds on the path parameter alone: |sd| <= velocity (1/s), |sdd| <= acceleration
    (1/s^2), |sddd| <= jerk (1/s^3)."""

    velocity: float
    acceleration: float
    jerk: float


def scalar_limits(constraints: PathConstraints) -> ScalarLimits | None:
    """The path-parameter bounds of constraints that are the same along the whole path, or
    ``None`` where a row depends on the speed (b x, d sd or the jerk's q'' and q''' terms above
    rounding noise), the acceleration bounds are not symmetric about zero, or a bound is not
    finite and positive. Read at s = 0; the caller has checked that nothing changes along s."""
    assert constraints.jerk is not None  # jerk_limited always builds the jerk rows
    dq, ddq, dddq, limit = (np.asarray(array, dtype=float) for array in constraints.jerk)
    reference = float(np.abs(dq[0]).max(initial=0.0))
    if reference == 0.0:
        return None
    velocity = float(constraints.sd_max[0])
    a, b, c, d = (np.asarray(array, dtype=float)[0] for array in (constraints.a, constraints.b, constraints.c, constraints.d))
    lower, upper = np.asarray(constraints.lower, dtype=float)[0], np.asarray(constraints.upper, dtype=float)[0]
    scale = max(float(np.abs(a).max(initial=0.0)), reference)
    if np.any(np.abs(b) > NOISE * scale) or np.any(np.abs(d) > NOISE * scale):
        return None
    if np.any(np.abs(ddq) > NOISE * reference) or np.any(np.abs(dddq) > NOISE * reference):
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        high = np.where(a > 0, (upper - c) / a, np.where(a < 0, (lower - c) / a, np.inf))
        low = np.where(a > 0, (lower - c) / a, np.where(a < 0, (upper - c) / a, -np.inf))
        jerk = np.where(dq[0] != 0.0, limit / np.abs(dq[0]), np.inf)
    if np.any((a == 0) & ((c < lower) | (c > upper))):
        return None
    u_high, u_low = float(np.min(high, initial=np.inf)), float(np.max(low, initial=-np.inf))
    j = float(np.min(jerk, initial=np.inf))
    if abs(u_high + u_low) > SYMMETRY * max(abs(u_high), abs(u_low)):
        return None
    bounds = ScalarLimits(velocity, u_high, j)
    if not (np.isfinite(j) and all(value > 0.0 for value in bounds)):
        return None
    return bounds


def double_s(length: float, limits: ScalarLimits) -> tuple[np.ndarray, np.ndarray]:
    """Durations (s) and jerks (1/s^3) of the segments of the time-optimal rest-to-rest motion
    over ``length`` (> 0) under ``limits`` (module docstring; the velocity and the acceleration
    bound may be infinite, the jerk bound is finite), zero-duration segments left out."""
    v, a, j = limits
    # With V (A) infinite the profile never reaches it: the cases below then never apply.
    reach_a = v * j >= a * a
    ta = (a / j + v / a if reach_a else 2.0 * np.sqrt(v / j)) if np.isfinite(v) else np.inf
    if length >= v * ta:
        tj = a / j if reach_a else np.sqrt(v / j)
        cruise = length / v - ta
    elif np.isfinite(a) and length >= 2.0 * a**3 / j**2:
        tj = a / j
        ta = 0.5 * (tj + np.sqrt(tj * tj + 4.0 * length / a))
        cruise = 0.0
    else:
        tj = np.cbrt(length / (2.0 * j))
        ta, cruise = 2.0 * tj, 0.0
    hold = max(ta - 2.0 * tj, 0.0)
    durations = np.array([tj, hold, tj, cruise, tj, hold, tj])
    jerks = np.array([j, 0.0, -j, 0.0, -j, 0.0, j])
    keep = durations > 0.0
    return durations[keep], jerks[keep]


def closed_form_timing(constraints: PathConstraints) -> JerkSegmentsTiming | None:
    """The double-S motion of s from rest at 0 to rest at 1 under ``constraints`` (limits the
    same along the path, ends at rest), or ``None`` where they do not reduce to scalar bounds
    (``scalar_limits``)."""
    limits = scalar_limits(constraints)
    if limits is None:
        return None
    durations, jerks = double_s(1.0, limits)
    timing = JerkSegmentsTiming(
        durations, jerks, optimality_gap=0.0,
        gap_basis="exact: the closed-form double-S profile (Biagiotti & Melchiorri §3.4) of limits the same along the path",
    )
    # The end state is exact up to rounding; put s = 1 exactly at the end (s is linear in the
    # jerks from rest).
    end = timing.starts[-1][0]
    return JerkSegmentsTiming(
        durations, jerks / end, optimality_gap=timing.optimality_gap, gap_basis=timing.gap_basis
    )
