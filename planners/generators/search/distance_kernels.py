"""Compiled arm-to-obstacle distances for the search (``free_space.point_distances``): the link
capsules' end points at many configurations (the forward kinematics of a chain of revolute and
prismatic joints, Rodrigues' formula per joint) and their signed distances to one obstacle, the
same computations as ``free_space.joint_placements`` and ``toptraj.planners.collision.distance`` in
numpy (sphere: point to segment; capsule: segment to segment, Ericson §5.1.9; box: golden
section along the segment of the convex signed distance, exact where the ball bound cannot
decide), one configuration at a time without temporaries.

Shapes: q (k, n_dof) in rad or m; capsule ends (k, C, 3) in m; distances (k,) in m.
"""

from __future__ import annotations

import math

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.collision.obstacles import BoxObstacle, CapsuleObstacle, Obstacle, SphereObstacle

SPHERE, CAPSULE, BOX = 0, 1, 2
#: Steps of the golden-section search along a segment (as ``toptraj.planners.collision.distance``).
GOLDEN_STEPS = 28
_RATIO = (math.sqrt(5.0) - 1.0) / 2.0
_TINY = 1e-18


def obstacle_row(obstacle: Obstacle) -> tuple[int, np.ndarray]:
    """The obstacle as (kind, parameters (18,)): center or a (3), b (3), radius, half sizes
    (3), rotation (9, row-major)."""
    row = np.zeros(19)
    if isinstance(obstacle, SphereObstacle):
        row[0:3], row[6] = obstacle.center, obstacle.radius
        return SPHERE, row
    if isinstance(obstacle, CapsuleObstacle):
        row[0:3], row[3:6], row[6] = obstacle.a, obstacle.b, obstacle.radius
        return CAPSULE, row
    if isinstance(obstacle, BoxObstacle):
        row[0:3], row[7:10] = obstacle.center, np.asarray(obstacle.size, dtype=float) / 2.0
        row[10:19] = np.asarray(obstacle.rotation, dtype=float).ravel()
        row[6] = float(np.linalg.norm(obstacle.size)) / 2.0
        return BOX, row
    raise TypeError(f"unknown obstacle {obstacle!r}")


@njit(cache=True, nogil=True)
def capsule_ends(q, parent, rotation0, translation0, prismatic, axis, index, joint, local_a, local_b):  # pragma: no cover - compiled
    """End points a, b (k, C, 3) of the capsules (attached to ``joint`` (C,), local ends
    ``local_a``, ``local_b`` (C, 3)) at configurations q (k, n): joint j's frame is its
    parent's times its placement (``rotation0`` (J, 3, 3), ``translation0`` (J, 3)) times its
    motion about or along ``axis`` (J, 3) by q[:, index[j]]."""
    k, n_joints, n_caps = q.shape[0], parent.shape[0], joint.shape[0]
    a = np.empty((k, n_caps, 3))
    b = np.empty((k, n_caps, 3))
    rot = np.zeros((n_joints, 3, 3))
    trans = np.zeros((n_joints, 3))
    base = np.empty((3, 3))
    turn = np.empty((3, 3))
    for row in range(k):
        for i in range(3):
            for m in range(3):
                rot[0, i, m] = 1.0 if i == m else 0.0
            trans[0, i] = 0.0
        for j in range(1, n_joints):
            p = parent[j]
            for i in range(3):
                trans[j, i] = trans[p, i]
                for m in range(3):
                    trans[j, i] += rot[p, i, m] * translation0[j, m]
                    total = 0.0
                    for w in range(3):
                        total += rot[p, i, w] * rotation0[j, w, m]
                    base[i, m] = total
            value = q[row, index[j]]
            x, y, z = axis[j, 0], axis[j, 1], axis[j, 2]
            if prismatic[j]:
                for i in range(3):
                    trans[j, i] += value * (base[i, 0] * x + base[i, 1] * y + base[i, 2] * z)
                    for m in range(3):
                        rot[j, i, m] = base[i, m]
                continue
            s, c = math.sin(value), 1.0 - math.cos(value)
            # I + s K + c K^2 with K the cross-product matrix of the axis
            turn[0, 0], turn[0, 1], turn[0, 2] = 1.0 - c * (y * y + z * z), -s * z + c * x * y, s * y + c * x * z
            turn[1, 0], turn[1, 1], turn[1, 2] = s * z + c * x * y, 1.0 - c * (x * x + z * z), -s * x + c * y * z
            turn[2, 0], turn[2, 1], turn[2, 2] = -s * y + c * x * z, s * x + c * y * z, 1.0 - c * (x * x + y * y)
            for i in range(3):
                for m in range(3):
                    rot[j, i, m] = base[i, 0] * turn[0, m] + base[i, 1] * turn[1, m] + base[i, 2] * turn[2, m]
        for cap in range(n_caps):
            j = joint[cap]
            for i in range(3):
                a[row, cap, i] = trans[j, i] + rot[j, i, 0] * local_a[cap, 0] + rot[j, i, 1] * local_a[cap, 1] + rot[j, i, 2] * local_a[cap, 2]
                b[row, cap, i] = trans[j, i] + rot[j, i, 0] * local_b[cap, 0] + rot[j, i, 1] * local_b[cap, 1] + rot[j, i, 2] * local_b[cap, 2]
    return a, b


@njit(cache=True, nogil=True)
def _point_segment(p, a, b):  # pragma: no cover - compiled
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    length2 = ab0 * ab0 + ab1 * ab1 + ab2 * ab2
    t = 0.0
    if length2 > 0.0:
        t = ((p[0] - a[0]) * ab0 + (p[1] - a[1]) * ab1 + (p[2] - a[2]) * ab2) / length2
        t = min(max(t, 0.0), 1.0)
    d0, d1, d2 = p[0] - (a[0] + t * ab0), p[1] - (a[1] + t * ab1), p[2] - (a[2] + t * ab2)
    return math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit(cache=True, nogil=True)
def _box_at(la0, la1, la2, lb0, lb1, lb2, h0, h1, h2, t):  # pragma: no cover - compiled
    """The box's signed distance at a + t (b - a), ends and half sizes in the box's frame."""
    outside, inside = 0.0, -np.inf
    excess = abs(la0 + t * (lb0 - la0)) - h0
    if excess > 0.0:
        outside += excess * excess
    inside = max(inside, excess)
    excess = abs(la1 + t * (lb1 - la1)) - h1
    if excess > 0.0:
        outside += excess * excess
    inside = max(inside, excess)
    excess = abs(la2 + t * (lb2 - la2)) - h2
    if excess > 0.0:
        outside += excess * excess
    inside = max(inside, excess)
    return math.sqrt(outside) + min(inside, 0.0)


@njit(cache=True, nogil=True)
def _in_box_frame(a, b, i, c, row, local):  # pragma: no cover - compiled
    """The ends a[i, c], b[i, c] in the box's frame (``obstacle_row``) into ``local`` (6,)."""
    for m in range(3):
        local[m] = (a[i, c, 0] - row[0]) * row[10 + m] + (a[i, c, 1] - row[1]) * row[13 + m] + (a[i, c, 2] - row[2]) * row[16 + m]
        local[3 + m] = (b[i, c, 0] - row[0]) * row[10 + m] + (b[i, c, 1] - row[1]) * row[13 + m] + (b[i, c, 2] - row[2]) * row[16 + m]


@njit(cache=True, nogil=True)
def box_bound(local, row):  # pragma: no cover - compiled
    """A lower bound on the box's signed distance along the segment with ends ``local`` (6,:
    a then b, in the box's frame): along each axis of the box, the least |coordinate| over the
    segment (0 where it crosses the plane through the center) less the half size bounds that
    axis's excess at every point, and the signed distance grows with each excess."""
    outside, inside = 0.0, -np.inf
    for m in range(3):
        a, b = local[m], local[3 + m]
        least = 0.0 if a * b <= 0.0 else min(abs(a), abs(b))
        excess = least - row[7 + m]
        if excess > 0.0:
            outside += excess * excess
        inside = max(inside, excess)
    return math.sqrt(outside) + min(inside, 0.0)


@njit(cache=True, nogil=True)
def segment_box(local, row):  # pragma: no cover - compiled
    """The box's signed distance along the segment with ends ``local`` (6,, the box's frame):
    golden section on [0, 1] of the convex signed distance, with both ends."""
    la0, la1, la2, lb0, lb1, lb2 = local[0], local[1], local[2], local[3], local[4], local[5]
    h0, h1, h2 = row[7], row[8], row[9]
    lo, hi = 0.0, 1.0
    for _ in range(GOLDEN_STEPS):
        c, d = hi - _RATIO * (hi - lo), lo + _RATIO * (hi - lo)
        if _box_at(la0, la1, la2, lb0, lb1, lb2, h0, h1, h2, c) < _box_at(la0, la1, la2, lb0, lb1, lb2, h0, h1, h2, d):
            hi = d
        else:
            lo = c
    return min(
        _box_at(la0, la1, la2, lb0, lb1, lb2, h0, h1, h2, (lo + hi) / 2.0),
        _box_at(la0, la1, la2, lb0, lb1, lb2, h0, h1, h2, 0.0),
        _box_at(la0, la1, la2, lb0, lb1, lb2, h0, h1, h2, 1.0),
    )


#: Below this (m), a bound is not trusted to prove an exact distance larger than a smaller one
#: (their roundings differ by far less).
BOUND_SLACK = 1e-9


@njit(cache=True, nogil=True)
def lower_distances(a, b, radius, kind, row, exact_below, nearest):  # pragma: no cover - compiled
    """``nearest`` (k,) lowered to each configuration's least signed distance of its capsules
    (a, b (k, C, 3), ``radius`` (C,)) to the obstacle (``obstacle_row``). For a box, the
    distance is exact where its ball bound is below ``exact_below`` or below the least
    distance to its center over all the configurations given, a lower bound elsewhere.

    A box's exact distance (``segment_box``, a golden section) is computed only for the
    capsules whose lower bound (the larger of the ball bound and ``box_bound``) may still lower
    the configuration's least: the least first, the others against it. The least is the
    same as with every exact distance computed, to the last bit."""
    k, n_caps = a.shape[0], a.shape[1]
    center = row[0:3]
    if kind == SPHERE:
        for i in range(k):
            for c in range(n_caps):
                nearest[i] = min(nearest[i], _point_segment(center, a[i, c], b[i, c]) - radius[c] - row[6])
        return
    if kind == CAPSULE:
        for i in range(k):
            for c in range(n_caps):
                nearest[i] = min(nearest[i], _segments(a[i, c], b[i, c], row[0:3], row[3:6]) - radius[c] - row[6])
        return
    to_center = np.empty((k, n_caps))
    least = np.inf
    for i in range(k):
        for c in range(n_caps):
            to_center[i, c] = _point_segment(center, a[i, c], b[i, c]) - radius[c]
            least = min(least, to_center[i, c])
    threshold = max(exact_below, least)
    local = np.empty((n_caps, 6))
    bound = np.empty(n_caps)
    for i in range(k):
        best = nearest[i]
        first = -1
        for c in range(n_caps):
            lower = to_center[i, c] - row[6]
            bound[c] = np.inf
            if lower >= threshold:
                best = min(best, lower)
                continue
            _in_box_frame(a, b, i, c, row, local[c])
            bound[c] = max(lower, box_bound(local[c], row) - radius[c])
            if first < 0 or bound[c] < bound[first]:
                first = c
        if first >= 0 and bound[first] - BOUND_SLACK < best:
            best = min(best, segment_box(local[first], row) - radius[first])
        for c in range(n_caps):
            if c != first and bound[c] - BOUND_SLACK < best:
                best = min(best, segment_box(local[c], row) - radius[c])
        nearest[i] = best


@njit(cache=True, nogil=True, inline="always")
def _closest(d1x, d1y, d1z, d2x, d2y, d2z, rx, ry, rz):  # pragma: no cover - compiled
    """The distance between segments p1 + s d1 and p2 + t d2 (s, t in [0, 1]) given their
    directions d1, d2 and r = p1 - p2 as scalars, the closest parameters clamped to the
    segments (Ericson, Real-Time Collision Detection, 5.1.9), without temporaries."""
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    c = d1x * rx + d1y * ry + d1z * rz
    b = d1x * d2x + d1y * d2y + d1z * d2z
    denom = a * e - b * b
    s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > _TINY else 0.0
    t = (b * s + f) / e if e > _TINY else 0.0
    if t < 0.0:
        s = min(max(-c / a, 0.0), 1.0) if a > _TINY else 0.0
    elif t > 1.0:
        s = min(max((b - c) / a, 0.0), 1.0) if a > _TINY else 0.0
    t = min(max(t, 0.0), 1.0)
    x, y, z = rx + s * d1x - t * d2x, ry + s * d1y - t * d2y, rz + s * d1z - t * d2z
    return math.sqrt(x * x + y * y + z * z)


@njit(cache=True, nogil=True)
def _segments(p1, q1, p2, q2):  # pragma: no cover - compiled
    """The distance between segments [p1, q1] and [p2, q2] (end points (3,) each), the closest
    parameters clamped to the segments (``_closest``)."""
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    return _closest(d1x, d1y, d1z, d2x, d2y, d2z, p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2])


@njit(cache=True, nogil=True)
def _capsules_apart(a, b, i, f, g):  # pragma: no cover - compiled
    """``_segments`` of the capsules f and g at configuration i of the ends a, b (k, C, 3), read
    from the arrays without views (``_closest``)."""
    d1x, d1y, d1z = b[i, f, 0] - a[i, f, 0], b[i, f, 1] - a[i, f, 1], b[i, f, 2] - a[i, f, 2]
    d2x, d2y, d2z = b[i, g, 0] - a[i, g, 0], b[i, g, 1] - a[i, g, 1], b[i, g, 2] - a[i, g, 2]
    return _closest(d1x, d1y, d1z, d2x, d2y, d2z, a[i, f, 0] - a[i, g, 0], a[i, f, 1] - a[i, g, 1], a[i, f, 2] - a[i, g, 2])


@njit(cache=True, nogil=True)
def pair_minimum(a, b, first, second, radius, out):  # pragma: no cover - compiled
    """Smallest signed distance (m) between the capsules ``first[p]`` and ``second[p]`` (m,),
    of radius sum ``radius[p]``, over the pairs, at each configuration of the capsule ends a, b
    (k, C, 3): into ``out`` (k,) (inf without pairs).

    A pair's segment distance is computed only where the bound by the balls around the two
    segments (center at the midpoint, radius half the length) may still lower the least: first
    the pair nearest at the configuration before, then the others against it. The least is
    the same as with every pair computed, to the last bit."""
    k, n_caps, n_pairs = a.shape[0], a.shape[1], first.shape[0]
    middle = np.empty((n_caps, 3))
    half = np.empty(n_caps)
    nearest_pair = 0
    for i in range(k):
        if n_pairs == 0:
            out[i] = np.inf
            continue
        for c in range(n_caps):
            length = 0.0
            for m in range(3):
                middle[c, m] = 0.5 * (a[i, c, m] + b[i, c, m])
                length += (b[i, c, m] - a[i, c, m]) ** 2
            half[c] = 0.5 * math.sqrt(length)
        best = _capsules_apart(a, b, i, first[nearest_pair], second[nearest_pair]) - radius[nearest_pair]
        for p in range(n_pairs):
            if p == nearest_pair:
                continue
            f, g = first[p], second[p]
            reach = best + half[f] + half[g] + radius[p] + BOUND_SLACK
            if reach <= 0.0:
                continue
            x, y, z = middle[f, 0] - middle[g, 0], middle[f, 1] - middle[g, 1], middle[f, 2] - middle[g, 2]
            if x * x + y * y + z * z >= reach * reach:
                continue
            d = _capsules_apart(a, b, i, f, g) - radius[p]
            if d < best:
                best, nearest_pair = d, p
        out[i] = best
