"""Compiled error estimates of the phase-plane method (numba): how much time each grid interval
of a conservative (interpolation) profile loses, from the midpoint discretization on the same grid,
from a switch inside the interval (``switch_excess``) and from the chord along a curved maximum
velocity curve, and the pieces each interval is split into so that the estimated duration error
falls to the tolerance (``refinement``, with ``toptraj.planners.timing.phase_plane.split_kernels``), and how far the limits
bulge between grid points (``row_excursions``). ``toptraj.planners.timing.phase_plane.method`` explains the
scheme; these loops hold no knowledge of paths or robots (``nogil``, cached on disk).
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.timing.phase_plane.split_kernels import _pieces

_INF = np.inf


@njit(cache=True, nogil=True, inline="always")
def _time_at_bounds(length, x0, x1, beta, alpha, c0, c1):  # pragma: no cover - compiled
    """Time over an interval of ``length`` from x0 to x1 (x = sd^2) at the bounds: accelerate
    at u = ``beta`` > 0 from x0, follow the ceiling c(t) (linear from c0 to c1), decelerate at
    u = ``alpha`` < 0 into x1. -1 where these bounds cannot join the two ends."""
    slope = (c1 - c0) / length
    # Acceleration meets the ceiling at t_a, the deceleration leaves it at t_d.
    t_a = (c0 - x0) / (2.0 * beta - slope) if 2.0 * beta > slope else length
    t_d = length - (c1 - x1) / (-2.0 * alpha + slope) if -2.0 * alpha + slope > 0.0 else 0.0
    if 0.0 <= t_a < t_d <= length:
        top_a = c0 + slope * t_a
        top_d = c0 + slope * t_d
        cruise = 2.0 * (t_d - t_a) / (np.sqrt(top_a) + np.sqrt(top_d))
        return (np.sqrt(top_a) - np.sqrt(x0)) / beta + cruise + (np.sqrt(top_d) - np.sqrt(x1)) / -alpha
    # Below the ceiling all the way: the two curves meet at t_m.
    t_m = (x1 - 2.0 * alpha * length - x0) / (2.0 * (beta - alpha))
    if not 0.0 <= t_m <= length:
        return -1.0
    top = x0 + 2.0 * beta * t_m
    return (np.sqrt(top) - np.sqrt(x0)) / beta + (np.sqrt(top) - np.sqrt(x1)) / -alpha


@njit(cache=True, nogil=True)
def switch_excess(ds, p, q, r, x, ceiling):  # pragma: no cover - compiled
    """How much faster than the discrete profile x (N + 1,) each interval could be crossed at
    its bounds (N,). With u constant per interval in the discrete profile, where the optimal
    profile switches inside an interval (starts from rest, reaches the maximum velocity curve,
    leaves it to decelerate), the constant-u interval is slower by an amount that a second
    discretization on the same grid does not see. The maximum path acceleration at x_i,
    the maximum deceleration at x_i+1 and the admissible upper x at the grid points
    (``ceiling``, N + 1, linear in between) stand for the interval's bounds."""
    n_stages, n_rows = p.shape
    excess = np.zeros(n_stages)
    for i in range(n_stages):
        x0 = x[i]
        x1 = x[i + 1]
        beta = _INF
        alpha = -_INF
        for k in range(n_rows):
            fastest = r[i, k] + q[i, k] * x0
            if fastest < beta:
                beta = fastest
            slowest = p[i, k] + q[i, k] * x1
            if slowest > alpha:
                alpha = slowest
        c0 = ceiling[i]
        c1 = ceiling[i + 1]
        if not (beta > 0.0 and alpha < 0.0 and beta < _INF and alpha > -_INF and c0 < _INF and c1 < _INF):
            continue
        c0 = max(c0, x0)
        c1 = max(c1, x1)
        if x0 + x1 <= 0.0:
            continue
        fast = _time_at_bounds(ds[i], x0, x1, beta, alpha, c0, c1)
        if fast >= 0.0:
            chord = 2.0 * ds[i] / (np.sqrt(x0) + np.sqrt(x1))
            if chord > fast:
                excess[i] = chord - fast
    return excess


@njit(cache=True, nogil=True, inline="always")
def _interval_time(ds, x0, x1):  # pragma: no cover - compiled
    """Time over an interval of length ds with x = sd^2 linear from x0 to x1."""
    total = np.sqrt(x0) + np.sqrt(x1)
    return 2.0 * ds / (total if total > 1e-300 else 1e-300)


@njit(cache=True, nogil=True)
def refinement(s, x, x_mid, ceiling, switch, tolerance, aim, guard, max_pieces, room):  # pragma: no cover - compiled
    """Error estimate of the profile x (N + 1,) on the grid s, and how finely to refine it.

    Each interval's error, this discretization's time minus the exact one, is estimated from:

    * first order: its time here minus its time in the midpoint discretization x_mid (second
      order, so it stands for the exact answer where the profile is resolved). The
      conservative discretization is the slower wherever both resolve the profile; where the
      midpoint one comes out slower, it does not resolve the interval either: that marks the
      interval (a second-order part below) but estimates no error of this profile;
    * second order: ``switch`` (N,), the time it would save by switching inside it
      (``switch_excess``, which neither discretization sees), and the chord error where the
      profile rides on the ``ceiling`` of admissible x (N + 1,) at both ends: x linear in s
      runs along the chord of the curved ceiling, which neither discretization checks between
      grid points. With x'' from second differences, the chord's time minus the curve's is
      -x'' ds^3 / (24 x^(3/2)) (faster under a convex ceiling, slower under a concave one).

    The estimated relative error is |the signed sum| plus ``guard`` times the magnitudes that
    may cancel in it or estimate nothing (chord errors, unresolved intervals): a guard against
    errors of the estimates themselves. Where it exceeds ``tolerance``, intervals are to be split
    into equal pieces: k pieces leave e / k of a first-order part and e / k^2 of a second-order
    one; the fewest whole pieces that bring the sum of both parts to ``aim`` times the tolerance
    over the estimate of its value (``_pieces``; at most ``max_pieces`` per interval and
    ``room`` new pieces in all).

    Returns the pieces wanted per interval (N,; all 1 when the estimate is within the
    tolerance), each interval's estimated error (N,, s: which to split first when the grid's
    cap allows fewer points, ``split_points``) and the estimated relative error.
    """
    n_stages = s.shape[0] - 1
    first = np.empty(n_stages)
    second = np.empty(n_stages)
    curvature = np.zeros(n_stages + 1)
    for i in range(1, n_stages):
        left = (ceiling[i] - ceiling[i - 1]) / (s[i] - s[i - 1])
        right = (ceiling[i + 1] - ceiling[i]) / (s[i + 1] - s[i])
        curvature[i] = 2.0 * (right - left) / (s[i + 1] - s[i - 1])
    if n_stages >= 2:
        curvature[0] = curvature[1]
        curvature[n_stages] = curvature[n_stages - 1]
    duration = 0.0
    signed = 0.0
    uncertain = 0.0
    for i in range(n_stages):
        ds = s[i + 1] - s[i]
        here = _interval_time(ds, x[i], x[i + 1])
        duration += here
        first[i] = here - _interval_time(ds, x_mid[i], x_mid[i + 1])
        chord = 0.0
        riding = (
            x[i] > 0.0
            and x[i + 1] > 0.0
            and x[i] >= ceiling[i] * (1.0 - 1e-6)
            and x[i + 1] >= ceiling[i + 1] * (1.0 - 1e-6)
            and ceiling[i] < _INF
            and ceiling[i + 1] < _INF
        )
        if riding:
            mean = 0.5 * (x[i] + x[i + 1])
            chord = -0.5 * (curvature[i] + curvature[i + 1]) * ds**3 / (24.0 * mean**1.5)
            if not np.isfinite(chord):
                chord = 0.0
        # The conservative discretization is slower than the exact profile wherever both
        # resolve it; where the midpoint one comes out slower, it is its own error (it does
        # not resolve the interval either), which marks the interval but is no estimate.
        unresolved = max(-first[i], 0.0)
        first[i] = max(first[i], 0.0)
        second[i] = switch[i] + abs(chord) + unresolved
        signed += first[i] + switch[i] + chord
        uncertain += abs(chord) + unresolved
    exact = duration - signed
    if not exact > 0.0:
        exact = duration
    error = (abs(signed) + guard * uncertain) / exact
    wanted = np.ones(n_stages)
    if error > tolerance:
        shrink = aim * tolerance / error
        _pieces(first, second, shrink, max_pieces, room, wanted)
    return wanted, first + second, error


@njit(cache=True, nogil=True)
def lagrange_weights(nodes, count, at, weights):  # pragma: no cover - compiled
    """Write into ``weights[:count]`` the Lagrange weights of the polynomial through
    ``nodes[:count]`` evaluated at ``at``."""
    for j in range(count):
        weight = 1.0
        for k in range(count):
            if k != j:
                weight *= (at - nodes[k]) / (nodes[j] - nodes[k])
        weights[j] = weight


#: Where within an interval (fractions of its width) ``row_excursions`` looks: a parabolic
#: excursion, wherever its peak lies, comes within an eighth of the interval of one of them.
_INNER = (0.25, 0.5, 0.75)
#: A limit is looked at between two grid points only where it is used to within this fraction
#: at one of them: a bulge of more than this within one interval would need curvatures no
#: spline of the grid's resolution has (and the dense check stays the judge).
_NEAR = 0.05


@njit(cache=True, nogil=True)
def _row_value(a, b, c, d, point, k, u, x, sd):  # pragma: no cover - compiled
    """``a u + b x + c + d sd`` of row k at grid point ``point``."""
    return a[point, k] * u + b[point, k] * x + c[point, k] + d[point, k] * sd


@njit(cache=True, nogil=True)
def _excess(value, lower, upper):  # pragma: no cover - compiled
    """How far ``value`` lies beyond [lower, upper], relative to the larger finite bound; -inf
    where neither bound is finite."""
    scale = 0.0
    if upper < _INF:
        scale = abs(upper)
    if lower > -_INF:
        scale = max(scale, abs(lower))
    if scale <= 0.0:
        return -_INF
    return max(value - upper, lower - value) / scale


@njit(cache=True, nogil=True)
def row_excursions(s, a, b, c, d, a_left, b_left, c_left, d_left, lower, upper, x_bound, binding, smooth, x, target, max_pieces):  # pragma: no cover - compiled
    """The fewest pieces (N,) into which each interval of the profile x (N + 1,) on the grid s
    must be split for its rows and its first-order bound x <= ``x_bound`` (N + 1,) to stay
    within ``target`` (relative to the limit) of their bounds at its quarter points; ``binding``
    (N + 1,) names the joint whose velocity limit sets x_bound at each grid point, ``smooth``
    (N + 1,) marks the grid points through which the rows are smooth (no knot of the path, no
    jump; ``toptraj.planners.constraints.torque_interpolation.smooth_points``).

    The interpolation discretization holds every row ``a u + b x + c + d sd`` at both ends of
    an interval (u constant, x linear in s); between them the row departs from the chord of its
    end values by about -r'' ds^2 / 8 at the middle, with r'' from the curvature of a, b, c
    and d along s. At the quarter points the row is the cubic, in s, through its values (at
    the interval's u and x there) at the two ends and at their outer neighbours, each seen from
    this interval's side; a quadratic where a knot of the path or a jump of the rows stands
    beyond an end, nothing where both do. No dynamics is evaluated. Likewise the speed:
    x_bound = sd_max^2 is least where a joint's |q'| / v peaks, often between grid points, and
    the velocity reaches sqrt(x / x_bound) of its limit, with 1 / x_bound from the same nodes
    where the joint that binds at both ends binds (it is smooth along one joint's bound only).
    Only limits used to within ``_NEAR`` at an end of the interval are looked at. The excursion
    falls with the square of the piece length: k pieces leave e / k^2 of an excess e, so
    k = ceil(sqrt(e / target)), at most ``max_pieces``. The dense limit check
    (``toptraj.planners.checks.gate``) stays the judge; this only keeps the grid fine where the limits curve.
    """
    n_stages = s.shape[0] - 1
    n_rows = a.shape[1]
    least = np.ones(n_stages)
    nodes = np.empty(4)
    points = np.empty(4, dtype=np.int64)
    weights = np.empty(4)
    speed_nodes = np.empty(4)
    inverse_bound = np.empty(4)
    speed_weights = np.empty(4)
    near = np.empty(n_rows, dtype=np.bool_)
    for i in range(n_stages):
        h = s[i + 1] - s[i]
        if h <= 0.0:
            continue
        u = (x[i + 1] - x[i]) / (2.0 * h)
        sd_start, sd_end = np.sqrt(max(x[i], 0.0)), np.sqrt(max(x[i + 1], 0.0))
        any_near = False
        for k in range(n_rows):
            start = _excess(_row_value(a, b, c, d, i, k, u, x[i], sd_start), lower[i, k], upper[i, k])
            end = _excess(_row_value(a_left, b_left, c_left, d_left, i + 1, k, u, x[i + 1], sd_end), lower[i, k], upper[i, k])
            near[k] = max(start, end) >= -_NEAR
            any_near = any_near or near[k]
        speed_near = binding[i] >= 0 and binding[i] == binding[i + 1] and (
            x[i] >= (1.0 - _NEAR) ** 2 * x_bound[i] or x[i + 1] >= (1.0 - _NEAR) ** 2 * x_bound[i + 1]
        )
        if not (any_near or speed_near):
            continue
        # The nodes: the interval's ends and their outer neighbours where the rows are smooth.
        count = 0
        if i >= 1 and smooth[i]:
            points[count] = i - 1
            count += 1
        points[count] = i
        points[count + 1] = i + 1
        count += 2
        if i + 2 <= n_stages and smooth[i + 1]:
            points[count] = i + 2
            count += 1
        if count < 3:
            continue
        for node in range(count):
            nodes[node] = s[points[node]]
        speed_count = 0
        if speed_near:
            for node in range(count):
                bound = x_bound[points[node]]
                if binding[points[node]] == binding[i] and bound > 0.0:
                    speed_nodes[speed_count] = nodes[node]
                    inverse_bound[speed_count] = 1.0 / bound if bound < _INF else 0.0
                    speed_count += 1
        worst = 0.0
        for fraction in _INNER:
            at = s[i] + fraction * h
            x_at = x[i] + fraction * (x[i + 1] - x[i])
            if speed_count >= 2 and x_at > 0.0:
                lagrange_weights(speed_nodes, speed_count, at, speed_weights)
                inverse = 0.0
                for node in range(speed_count):
                    inverse += speed_weights[node] * inverse_bound[node]
                if inverse > 0.0:
                    worst = max(worst, np.sqrt(x_at * inverse) - 1.0)
            if not any_near:
                continue
            sd_at = np.sqrt(max(x_at, 0.0))
            lagrange_weights(nodes, count, at, weights)
            for k in range(n_rows):
                if not near[k]:
                    continue
                value = 0.0
                for node in range(count):
                    point = points[node]
                    # The rows at an interval's far end (and beyond it) as seen from the left.
                    if point > i:
                        value += weights[node] * _row_value(a_left, b_left, c_left, d_left, point, k, u, x_at, sd_at)
                    else:
                        value += weights[node] * _row_value(a, b, c, d, point, k, u, x_at, sd_at)
                worst = max(worst, _excess(value, lower[i, k], upper[i, k]))
        if worst > target:
            least[i] = min(np.ceil(np.sqrt(worst / target)), max_pieces)
    return least
