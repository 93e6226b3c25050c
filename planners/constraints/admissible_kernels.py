"""Compiled inner loops of the phase-plane method (numba): the per-point admissible interval of
x = sd^2, the bounds on u of each grid interval in either discretization (the sweeps over
them: ``toptraj.planners.timing.phase_plane.sweep_kernels``) and the zero-inertia test of an interval's rows. Plain loops
over small row counts, compiled once (``nogil``, so threads run them in parallel) and cached on
disk; they hold no knowledge of paths or robots.

Bounds on the path acceleration u come as lines: ``p + q x <= u <= r + q x`` per row, shape
(N, m), with an intercept of -inf (p) or +inf (r) where a row gives no such bound (the two lines
of a row share their slope q = -b / a).
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit

_INF = np.inf
#: |a| below this fraction of the row's scale |a| + |b| counts as zero (a zero-inertia point).
ZERO_INERTIA = 1e-10


@njit(cache=True, nogil=True, inline="always")
def _gap(p, q, r, w, i, x):  # pragma: no cover - compiled
    """phi(x) = min_j (r_j + w_j x) - max_k (p_k + q_k x) at point i, its slope there, and the
    intercept of the active piece (so its root is -intercept / slope without cancellation)."""
    n_rows = p.shape[1]
    lowest = -_INF
    low_slope = 0.0
    low_intercept = 0.0
    highest = _INF
    high_slope = 0.0
    high_intercept = 0.0
    for k in range(n_rows):
        if p[i, k] != -_INF:
            value = p[i, k] + q[i, k] * x
            if value > lowest:
                lowest = value
                low_slope = q[i, k]
                low_intercept = p[i, k]
        if r[i, k] != _INF:
            value = r[i, k] + w[i, k] * x
            if value < highest:
                highest = value
                high_slope = w[i, k]
                high_intercept = r[i, k]
    return highest - lowest, high_slope - low_slope, high_intercept - low_intercept


#: ``interval_bounds``'s ``kept`` and ``before`` when nothing is kept from an earlier grid.
NOTHING_KEPT = np.empty(0, dtype=np.int64)
NOTHING_BEFORE = (np.empty((0, 0)), np.empty((0, 0)), np.empty((0, 0)), np.empty(0), np.empty(0))
#: Stand-in for an unbounded x = sd^2 in the root search (sd = 1e6 1/s).
_X_FAR = 1e12


@njit(cache=True, nogil=True)
def admissible_intervals(p, q, r, w, x_low, x_high, skip):  # pragma: no cover - compiled
    """Narrow ``[x_low, x_high]`` (each (N,), updated in place and returned) at every point but
    those ``skip`` (N,) marks to the x for which some u lies between every lower and every upper
    line.

    phi(x) = min_j (r_j + w_j x) - max_k (p_k + q_k x) is concave and piecewise linear, and the
    admissible x are where phi >= 0. Started right of the interval (where phi < 0 falls), Newton's
    method on a concave piecewise-linear function steps along one linear piece at a time without
    overshooting the largest root; started left of it, likewise to the smallest root. A few
    steps find each end exactly. An empty interval is marked by x_high = -1.
    """
    n_points = p.shape[0]
    for i in range(n_points):
        if skip[i]:
            continue
        low = x_low[i]
        high = x_high[i]
        unbounded = high > _X_FAR
        x = _X_FAR if unbounded else high
        if x < low:
            x_high[i] = -1.0
            continue
        empty = False
        for _ in range(100):
            gap, slope, intercept = _gap(p, q, r, w, i, x)
            if gap >= -1e-12 * (1.0 + abs(x)):
                break
            if slope >= 0.0:
                empty = True
                break
            x = -intercept / slope
            if x < low - 1e-12 * (1.0 + abs(low)):
                empty = True
                break
        if empty:
            x_high[i] = -1.0
            continue
        x_high[i] = high if (unbounded and x == _X_FAR) else x
        x = low
        for _ in range(100):
            gap, slope, intercept = _gap(p, q, r, w, i, x)
            if gap >= -1e-12 * (1.0 + abs(x)):
                break
            if slope <= 0.0:
                x_high[i] = -1.0
                break
            x = -intercept / slope
        x_low[i] = x
    return x_low, x_high


@njit(cache=True, nogil=True, inline="always")
def _row_bounds(a, b, c, lo, hi):  # pragma: no cover - compiled
    """Row ``lo <= a u + b x + c <= hi`` as bounds on u, ``low + slope x <= u <= high + slope x``:
    (low, slope, high, False), NaN intercepts read as no bound. A zero-inertia row (a = 0)
    bounds x instead: (x_from, 0, x_to, True), the x it admits, ``-inf, inf`` when b = 0 and the
    row holds, ``inf, -inf`` (none) when b = 0 and it fails."""
    scale = abs(a) + abs(b)
    if scale < 1e-300:
        scale = 1e-300
    if abs(a) <= ZERO_INERTIA * scale:
        if b > 0.0:
            return (lo - c) / b, 0.0, (hi - c) / b, True
        if b < 0.0:
            return (hi - c) / b, 0.0, (lo - c) / b, True
        if c > hi or c < lo:
            return _INF, 0.0, -_INF, True
        return -_INF, 0.0, _INF, True
    # One division per row: the three quotients by a as products with 1 / a (within an ulp of
    # the quotients; the sweeps' loops are bound by the divisions).
    inverse = 1.0 / a
    from_upper = (hi - c) * inverse
    from_lower = (lo - c) * inverse
    if a > 0.0:
        low, high = from_lower, from_upper
    else:
        low, high = from_upper, from_lower
    if low != low:
        low = -_INF
    if high != high:
        high = _INF
    return low, -b * inverse, high, False


@njit(cache=True, nogil=True)
def _zero_inertia(i, k, x_from, x_to, p, q, r, x_low, x_high):  # pragma: no cover - compiled
    """A zero-inertia row k at point (or interval) i, which admits x in [x_from, x_to]
    (``_row_bounds``): no bound on u in its column, ``x_low[i], x_high[i]`` narrowed to it.
    Returns whether the row fails at every x."""
    p[i, k] = -_INF
    q[i, k] = 0.0
    r[i, k] = _INF
    if x_from > x_to:
        return True
    if x_to < x_high[i]:
        x_high[i] = x_to
    if x_from > x_low[i]:
        x_low[i] = x_from
    return False


@njit(cache=True, nogil=True)
def point_bounds(a, b, c, lower, upper, x_bound):  # pragma: no cover - compiled
    """Every row of every point (each (N, m)) as bounds on u, and the admissible x of each point
    under them and ``x <= x_bound`` (N,).

    Returns p, q, r (N, m; the upper lines share the slope q), x_low, x_high (N,; x_high = -1
    where no x is admissible), singular (N, m: rows with a = 0) and static_fail (N,: a row with
    a = b = 0 that fails at every x).
    """
    n_points, n_rows = a.shape
    p = np.empty((n_points, n_rows))
    q = np.empty((n_points, n_rows))
    r = np.empty((n_points, n_rows))
    x_low = np.zeros(n_points)
    x_high = np.empty(n_points)
    singular = np.zeros((n_points, n_rows), dtype=np.bool_)
    static_fail = np.zeros(n_points, dtype=np.bool_)
    for i in range(n_points):
        x_high[i] = x_bound[i]
        for k in range(n_rows):
            low, slope, high, is_singular = _row_bounds(a[i, k], b[i, k], c[i, k], lower[i, k], upper[i, k])
            if is_singular:
                singular[i, k] = True
                if _zero_inertia(i, k, low, high, p, q, r, x_low, x_high):
                    static_fail[i] = True
            else:
                p[i, k] = low
                q[i, k] = slope
                r[i, k] = high
    admissible_intervals(p, q, r, q, x_low, x_high, np.zeros(n_points, dtype=np.bool_))
    for i in range(n_points):
        if static_fail[i] or x_low[i] > x_high[i]:
            x_high[i] = -1.0
    return p, q, r, x_low, x_high, singular, static_fail


@njit(cache=True, nogil=True)
def _friction_share(d, root, half):  # pragma: no cover - compiled
    """The terms (to b, to c) that replace a viscous term ``d sd`` in one half of a row
    linearized around sd_ref = ``root``: the tangent d (x + x_ref) / (2 sd_ref) of the concave
    d sqrt(x) where it can only tighten the row, and 0 elsewhere (``PathConstraints.linearized``:
    half 0 is the row against its upper bound, which takes d > 0; half 1 against its lower
    bound, which takes d < 0)."""
    share = max(d, 0.0) if half == 0 else min(d, 0.0)
    return share / (2.0 * root), 0.5 * share * root


@njit(cache=True, nogil=True)
def _singular_row(i, column, x_from, x_to, p, q, r, x_low, x_high, singular, static_fail):  # pragma: no cover - compiled
    """A zero-inertia row of interval i (``_row_bounds``: it admits x in [x_from, x_to]) in
    ``column``: no bound on u there, the interval's admissible x narrowed, the interval marked
    singular, and failed when the row fails at every x. (Rare, so the arrays it takes cost
    nothing: numba counts the references of arrays passed to a call, which made a helper
    called for every row five times slower than storing in place.)"""
    singular[i] = True
    if _zero_inertia(i, column, x_from, x_to, p, q, r, x_low, x_high):
        static_fail[i] = True


@njit(cache=True, nogil=True)
def _frictionless_bounds(s, ra, rb, rc, la, lb, lc, lower, upper, midpoint, skip, p, q, r, x_low, x_high, singular, static_fail):  # pragma: no cover - compiled
    """``interval_bounds`` without viscous friction, into ``p, q, r`` (N, m midpoint, 2 m
    interpolation) and ``x_low, x_high, singular, static_fail`` (N,): one line per row at
    each end of an interval, or at its midpoint; intervals ``skip`` (N,) marks are left as
    they are."""
    n_rows = ra.shape[1]
    for i in range(s.shape[0] - 1):
        if skip[i]:
            continue
        ds = s[i + 1] - s[i]
        for j in range(n_rows):
            if midpoint:
                b_mid = 0.5 * (rb[i, j] + lb[i + 1, j])
                a_mid = 0.5 * (ra[i, j] + la[i + 1, j]) + ds * b_mid
                low, slope, high, is_singular = _row_bounds(a_mid, b_mid, 0.5 * (rc[i, j] + lc[i + 1, j]), lower[i, j], upper[i, j])
                p[i, j], q[i, j], r[i, j] = low, slope, high
                if is_singular:
                    _singular_row(i, j, low, high, p, q, r, x_low, x_high, singular, static_fail)
            else:
                low, slope, high, is_singular = _row_bounds(ra[i, j], rb[i, j], rc[i, j], lower[i, j], upper[i, j])
                p[i, j], q[i, j], r[i, j] = low, slope, high
                if is_singular:
                    _singular_row(i, j, low, high, p, q, r, x_low, x_high, singular, static_fail)
                b_next = lb[i + 1, j]
                a_next = la[i + 1, j] + 2.0 * ds * b_next
                low, slope, high, is_singular = _row_bounds(a_next, b_next, lc[i + 1, j], lower[i + 1, j], upper[i + 1, j])
                p[i, j + n_rows], q[i, j + n_rows], r[i, j + n_rows] = low, slope, high
                if is_singular:
                    _singular_row(i, j + n_rows, low, high, p, q, r, x_low, x_high, singular, static_fail)


@njit(cache=True, nogil=True)
def _friction_bounds(s, ra, rb, rc, rd, la, lb, lc, ld, lower, upper, x_ref, midpoint, p, q, r, x_low, x_high, singular, static_fail):  # pragma: no cover - compiled
    """``interval_bounds`` with viscous friction, into ``p, q, r`` (N, 2 m midpoint, 4 m
    interpolation) and ``x_low, x_high, singular, static_fail`` (N,): each row split into its
    half against the upper bound and its half against the lower bound, the viscous term of each
    replaced by its tangent at ``x_ref`` (``_friction_share``)."""
    n_rows = ra.shape[1]
    per_half = n_rows if midpoint else 2 * n_rows
    for i in range(s.shape[0] - 1):
        ds = s[i + 1] - s[i]
        root_here = np.sqrt(max(x_ref[i], 1e-6))
        root_next = np.sqrt(max(x_ref[i + 1], 1e-6))
        for half in range(2):
            for j in range(n_rows):
                to_b, to_c = _friction_share(rd[i, j], root_here, half)
                b_here, c_here = rb[i, j] + to_b, rc[i, j] + to_c
                to_b, to_c = _friction_share(ld[i + 1, j], root_next, half)
                b_next, c_next = lb[i + 1, j] + to_b, lc[i + 1, j] + to_c
                if half == 0:
                    lo_here, hi_here, lo_next, hi_next = -_INF, upper[i, j], -_INF, upper[i + 1, j]
                else:
                    lo_here, hi_here, lo_next, hi_next = lower[i, j], _INF, lower[i + 1, j], _INF
                k = half * per_half + j
                if midpoint:
                    b_mid = 0.5 * (b_here + b_next)
                    a_mid = 0.5 * (ra[i, j] + la[i + 1, j]) + ds * b_mid
                    low, slope, high, is_singular = _row_bounds(a_mid, b_mid, 0.5 * (c_here + c_next), lo_here, hi_here)
                    p[i, k], q[i, k], r[i, k] = low, slope, high
                    if is_singular:
                        _singular_row(i, k, low, high, p, q, r, x_low, x_high, singular, static_fail)
                else:
                    low, slope, high, is_singular = _row_bounds(ra[i, j], b_here, c_here, lo_here, hi_here)
                    p[i, k], q[i, k], r[i, k] = low, slope, high
                    if is_singular:
                        _singular_row(i, k, low, high, p, q, r, x_low, x_high, singular, static_fail)
                    a_next = la[i + 1, j] + 2.0 * ds * b_next
                    low, slope, high, is_singular = _row_bounds(a_next, b_next, c_next, lo_next, hi_next)
                    p[i, k + n_rows], q[i, k + n_rows], r[i, k + n_rows] = low, slope, high
                    if is_singular:
                        _singular_row(i, k + n_rows, low, high, p, q, r, x_low, x_high, singular, static_fail)


@njit(cache=True, nogil=True)
def interval_bounds(s, ra, rb, rc, rd, la, lb, lc, ld, lower, upper, x_bound, x_ref, friction, midpoint, kept, before):  # pragma: no cover - compiled
    """The rows of each grid interval i on its start state (u_i, x_i) as bounds on u, and the
    admissible x_i under them.

    Rows ``lo <= a u + b x + c + d sd <= hi`` are given at the grid points, each (N + 1, m):
    ``ra, rb, rc, rd`` as seen from the interval that starts at a point, ``la, lb, lc, ld`` from
    the one that ends there (they differ only at corners of the path). With x linear in s over
    the interval (x_i+1 = x_i + 2 ds u_i):

    * interpolation (``midpoint`` False): every row at s_i, ``ra_i u + rb_i x_i + rc_i``, and at
      s_i+1 as seen from the interval, ``la_i+1 u + lb_i+1 (x_i + 2 ds u) + lc_i+1``:
      conservative, the limits hold at every grid point (``phase_plane.grid.interval_rows``);
    * midpoint (``midpoint`` True): every row at the interval's midpoint with the coefficients
      averaged from its ends, ``a_m u + b_m (x_i + ds u) + c_m``: second-order accurate, no
      bound (``phase_plane.grid.midpoint_stage_rows``).

    With ``friction``, each row is first split into its halves against the upper and the lower
    bound, the viscous term of each replaced by its tangent at x_ref (N + 1,), exactly as
    ``PathConstraints.linearized`` does; without, ``rd, ld`` and ``x_ref`` are not read.

    ``kept`` (N,, or empty) names, for each interval, the same interval (the same ends, the same
    rows there) of an earlier grid whose bounds ``before`` (its p, q, r, x_low, x_high, as this
    returns them) holds, or -1: those are copied, not computed again (without friction, whose
    linearization point may have moved).

    Returns p, q, r (N, k m with k = 1 midpoint, 2 interpolation, times 2 with friction),
    x_low, x_high (N,; x_high = -1 where none is admissible, capped by ``x_bound[i]``) and
    singular (N,: the interval has a zero-inertia row, among those computed).
    """
    n_stages = s.shape[0] - 1
    n_rows = ra.shape[1]
    width = (2 if friction else 1) * (n_rows if midpoint else 2 * n_rows)
    p = np.empty((n_stages, width))
    q = np.empty((n_stages, width))
    r = np.empty((n_stages, width))
    x_low = np.zeros(n_stages)
    x_high = np.empty(n_stages)
    singular = np.zeros(n_stages, dtype=np.bool_)
    static_fail = np.zeros(n_stages, dtype=np.bool_)
    copied = np.zeros(n_stages, dtype=np.bool_)
    for i in range(n_stages):
        x_high[i] = x_bound[i]
        if kept.shape[0] and kept[i] >= 0 and not friction:
            k = kept[i]
            p[i, :] = before[0][k]
            q[i, :] = before[1][k]
            r[i, :] = before[2][k]
            x_low[i] = before[3][k]
            x_high[i] = before[4][k]
            copied[i] = True
    if friction:
        _friction_bounds(s, ra, rb, rc, rd, la, lb, lc, ld, lower, upper, x_ref, midpoint, p, q, r, x_low, x_high, singular, static_fail)
    else:
        _frictionless_bounds(s, ra, rb, rc, la, lb, lc, lower, upper, midpoint, copied, p, q, r, x_low, x_high, singular, static_fail)
    admissible_intervals(p, q, r, q, x_low, x_high, copied)
    for i in range(n_stages):
        if static_fail[i] or x_low[i] > x_high[i]:
            x_high[i] = -1.0
    return p, q, r, x_low, x_high, singular


@njit(cache=True, nogil=True)
def zero_inertia_intervals(s, a, b, a_left, b_left, intervals, threshold):  # pragma: no cover - compiled
    """Whether each of ``intervals`` (k,) of the grid s has a row of the interpolation
    discretization whose u-coefficient is within ``threshold`` of its scale |a| + |b| of zero:
    at the interval's start (a, b, each (N + 1, m)) or at its end as the interval sees it
    (a_left + 2 ds b_left, b_left; ``phase_plane.grid.interval_rows``), viscous friction left out;
    (k,) bool."""
    found = np.zeros(intervals.shape[0], dtype=np.bool_)
    for n in range(intervals.shape[0]):
        i = intervals[n]
        ds = s[i + 1] - s[i]
        for k in range(a.shape[1]):
            start = abs(a[i, k])
            end = abs(a_left[i + 1, k] + 2.0 * ds * b_left[i + 1, k])
            if start <= threshold * max(start + abs(b[i, k]), 1e-300) or end <= threshold * max(end + abs(b_left[i + 1, k]), 1e-300):
                found[n] = True
                break
    return found
