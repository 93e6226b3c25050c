"""The phase of constant path jerk at an end at rest, and the grid points of the jerk-limited
timing around it (``toptraj.planners.timing.jerk.method``).

An interval of the grid that starts (ends) at rest holds the motion of constant path jerk from
(to) rest, u = 2 x / (3 s) (``toptraj.planners.timing.jerk.scaling``), where intervals of linear
u cannot follow it (u grows as s^(1/3)). The grid therefore loses its points closer to the end
than half that phase (``opened``) and gains points around the phase's end (``graded``). A
constant path jerk sigma keeps the joint jerk

    qddd_k = q'_k sigma + 3 q''_k sd sdd + q'''_k sd^3

at its value at rest, q'_k(0) sigma, only while the path's coefficients change little and the
speed is low: where they do not (a long phase, under a low jerk limit, along a curved path),
the interval at rest keeps its jerk rows at both of its ends by lowering sigma over the whole
interval, and the answer lengthens far beyond what a second grid shows (a ur5 spline under a
jerk limit of 1 rad/s^3: 4.51 s, its stated gap 7e-4, where intervals of linear u over the
same stretch time it in 3.88 s). The interval at rest then ends where that change reaches
``HELD_FRACTION`` of the limit (``held_length``): ``opened`` keeps the grid's points beyond it,
and ``graded`` adds one there where the grid's first interval is longer (a named grid of 20
intervals on that spline: 4.27 s stated 8.3 % above the optimum, 10 % in fact; 3.92 s, 1.5 %
stated, 1.3 % in fact, with it).
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.timing.base import Boundary
from toptraj.planners.timing.jerk.accuracy import kept

#: Where the limits give no constant-jerk phase at an end at rest, the first interval is
#: this fraction of the grid's own first interval.
FALLBACK_FIRST_INTERVAL = 1e-3
#: The shortest first interval at an end at rest, as a fraction of the grid's own first interval.
MIN_FIRST_INTERVAL = 1e-5
#: Largest change of a joint's jerk along the constant path jerk of an interval at rest, as a
#: fraction of its limit, over which that interval may extend (``held_length``): on the ur5
#: example the phase changes it by 0.2 % (held); on the spline of the module docstring by 32 %
#: at half the phase (4.51 s there, 3.88 s once the interval at rest ends at 5 %).
HELD_FRACTION = 0.05
#: Grid points near an end at rest, as multiples of the length of its constant-jerk phase: the
#: first interval holds half the phase, the points around the phase's end resolve the switch.
_REST_POINTS = np.array([0.5, 0.7, 0.85, 1.0, 1.15, 1.3, 1.5, 1.75, 2.0, 2.5, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0])
#: Where ``graded`` looks for the end of the interval at rest within half the phase, as multiples
#: of the phase's length (halves of 0.5 down to 1/128 of it, by quarter octaves).
_HELD_CANDIDATES = 0.5 * 2.0 ** (-np.arange(0.0, 6.25, 0.25))


def _path_jerk(constraints: PathConstraints, point: int) -> float:
    """The largest path jerk (1/s^3) the jerk limits allow at grid point ``point`` while the
    motion is at rest: sigma = min_k J_k / |q'_k| (infinite where no limit binds)."""
    assert constraints.jerk is not None  # jerk_limited always builds the jerk rows
    dq, _, _, limit = constraints.jerk
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.nanmin(np.where(dq[point] != 0.0, limit / np.abs(dq[point]), np.inf)))


def start_phase(constraints: PathConstraints, point: int) -> float:
    """Length in s of the constant-jerk phase that starts (ends) the motion at rest at grid
    point ``point`` (0 or -1), were the path's coefficients constant: at the largest path jerk
    sigma (``_path_jerk``) until the largest path acceleration u_max allowed at rest,
    s = sigma t^3 / 6 with t = u_max / sigma."""
    sigma = _path_jerk(constraints, point)
    with np.errstate(divide="ignore", invalid="ignore"):
        a, c = constraints.a[point], constraints.c[point]
        lower, upper = constraints.lower[point], constraints.upper[point]
        u_bound = np.where(a > 0, (upper - c) / a, np.where(a < 0, (lower - c) / a, np.inf))
    u_max = float(np.min(u_bound, initial=np.inf))
    if not (np.isfinite(sigma) and sigma > 0.0 and np.isfinite(u_max) and u_max > 0.0):
        return np.inf
    t = u_max / sigma
    return sigma * t**3 / 6.0


def held_length(constraints: PathConstraints, point: int, length: float) -> float:
    """How far (s, at most ``length``) from the end at rest at grid point ``point`` (0 or -1) a
    constant path jerk sigma (``_path_jerk``) keeps every limited joint's jerk within
    ``HELD_FRACTION`` of its limit of its value at rest (module docstring): the distance of the
    first grid point where the change exceeds it, evaluated along s = sigma t^3 / 6
    (sd = sigma t^2 / 2, sdd = +-sigma t toward the inside)."""
    assert constraints.jerk is not None  # jerk_limited always builds the jerk rows
    dq, ddq, dddq, limit = constraints.jerk
    sigma = _path_jerk(constraints, point)
    distance = np.abs(constraints.s - constraints.s[point])
    inside = np.flatnonzero((distance > 0.0) & (distance < length))
    limited = np.isfinite(limit)
    if not (np.isfinite(sigma) and sigma > 0.0 and inside.size and limited.any()):
        return length
    t = np.cbrt(6.0 * distance[inside] / sigma)[:, None]
    sd, sdd = 0.5 * sigma * t**2, (1.0 if point == 0 else -1.0) * sigma * t
    change = (dq[inside] - dq[point]) * sigma + 3.0 * ddq[inside] * sd * sdd + dddq[inside] * sd**3
    beyond = np.any(np.abs(change[:, limited]) > HELD_FRACTION * limit[limited], axis=1)
    return float(distance[inside][beyond].min()) if beyond.any() else length


def opened(constraints: PathConstraints, boundary: Boundary) -> PathConstraints:
    """The grid without its points closer to an end at rest than half the constant-jerk phase
    there (``start_phase``), or than the length over which that phase holds (``held_length``;
    the path's knots kept): the interval at rest holds that phase's motion exactly, where
    intervals of linear u cannot follow it (u grows as s^(1/3)). A grid finer than the phase
    put them there: on the ur5 example, a named grid of 2,000 intervals answered 0.39 % above
    the optimum (0.08 % with them dropped)."""
    s = constraints.s
    knots = np.asarray(constraints.knots if constraints.knots is not None else [], dtype=float)
    keep = np.ones(len(s), dtype=bool)
    for at_rest, point, distance in ((boundary.sd_start == 0.0, 0, s - s[0]), (boundary.sd_end == 0.0, -1, s[-1] - s)):
        phase = start_phase(constraints, point) if at_rest else np.inf
        # Not across a knot: the path's coefficients change there, and the phase with them.
        if np.isfinite(phase) and not np.any((np.abs(knots - s[point]) > 0.0) & (np.abs(knots - s[point]) < 0.5 * phase)):
            keep &= (distance == 0.0) | (distance >= held_length(constraints, point, 0.5 * phase))
    if keep.all() or keep.sum() < 8:
        return constraints
    return kept(constraints, keep)


def graded(constraints: PathConstraints, boundary: Boundary) -> PathConstraints:
    """The grid with points added toward each end at rest around the end of the constant-jerk
    phase there (``start_phase``), and where that phase stops holding the joint jerk
    (``held_length``): the first interval, which holds the motion of constant jerk from rest,
    then ends within that phase (the points closer to the end than half of it, or than where
    it stops holding, are dropped before, ``opened``)."""
    if not constraints.can_refine:
        return constraints
    s = constraints.s
    pieces: list[np.ndarray] = []
    for at_rest, point, sign, room in (
        (boundary.sd_start == 0.0, 0, 1.0, s[1] - s[0]),
        (boundary.sd_end == 0.0, -1, -1.0, s[-1] - s[-2]),
    ):
        if not at_rest:
            continue
        # A phase shorter than the floor (a jerk limit far above what the other limits let
        # matter) would put grid points within rounding of the end, and rows of size 1 / h^2
        # into the program: the first interval is then the floor, over which the jerk limit
        # does not bind.
        phase = max(start_phase(constraints, point), room * MIN_FIRST_INTERVAL / _REST_POINTS[0])
        if not np.isfinite(phase):
            phase = room * FALLBACK_FIRST_INTERVAL / _REST_POINTS[0]
        offsets = phase * _REST_POINTS
        if np.isfinite(phase) and 0.5 * phase > 0.0:
            # Where the phase stops holding the joint jerk before half its length, the first
            # interval ends there (``held_length``, on candidate points within the first interval).
            candidates = phase * _HELD_CANDIDATES
            candidates = s[point] + sign * candidates[candidates < 0.9 * room]
            if candidates.size:
                held = held_length(constraints.with_points(np.unique(candidates)), point, 0.5 * phase)
                offsets = np.concatenate([[held], offsets]) if held < offsets[0] else offsets
        offsets = offsets[offsets < 0.9 * room]
        pieces.append(s[point] + sign * offsets)
    points = np.concatenate(pieces) if pieces else np.empty(0)
    extra = np.unique(points[~np.isin(points, s)])
    return constraints.with_points(extra) if extra.size else constraints
