"""Signed distances (m) between the robot's link capsules and obstacles, for many states at
once: capsule end points a, b of shape (..., 3) and radius r (...,); negative inside.

Sphere: the distance from its center to the segment; capsule: segment to segment (closest
points as in Ericson, *Real-Time Collision Detection*, §5.1.9); box: the signed distance to a
box is convex along the segment, minimized by golden-section search to 1e-5 of its length.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.collision.obstacles import BoxObstacle, CapsuleObstacle, Obstacle, SphereObstacle

_GOLDEN_STEPS = 28


def _point_segment(p, a, b):
    ab = b - a
    length2 = np.einsum("...i,...i->...", ab, ab)
    t = np.where(length2 > 0, np.einsum("...i,...i->...", p - a, ab) / np.where(length2 > 0, length2, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def _segment_segment(p1, q1, p2, q2):
    """Distance between segments [p1, q1] and [p2, q2] (broadcast over leading axes)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...i,...i->...", d1, d1)
    e = np.einsum("...i,...i->...", d2, d2)
    f = np.einsum("...i,...i->...", d2, r)
    c = np.einsum("...i,...i->...", d1, r)
    b = np.einsum("...i,...i->...", d1, d2)
    a, e, f, c, b = np.broadcast_arrays(a, e, f, c, b)
    tiny = 1e-18
    denom = a * e - b * b
    s = np.where(denom > tiny, np.clip((b * f - c * e) / np.where(denom > tiny, denom, 1.0), 0.0, 1.0), 0.0)
    t = np.where(e > tiny, (b * s + f) / np.where(e > tiny, e, 1.0), 0.0)
    # t outside [0, 1]: clamp it and recompute s
    s = np.where(t < 0.0, np.where(a > tiny, np.clip(-c / np.where(a > tiny, a, 1.0), 0.0, 1.0), 0.0), s)
    s = np.where(t > 1.0, np.where(a > tiny, np.clip((b - c) / np.where(a > tiny, a, 1.0), 0.0, 1.0), 0.0), s)
    t = np.clip(t, 0.0, 1.0)
    closest1 = p1 + s[..., None] * d1
    closest2 = p2 + t[..., None] * d2
    return np.linalg.norm(closest1 - closest2, axis=-1)


def segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Distance (m) between the segments [p1, q1] and [p2, q2], end points (..., 3) broadcast
    over the leading axes; shape: those axes."""
    return _segment_segment(p1, q1, p2, q2)


def _box_signed(points, half):
    """Signed distance of points (..., 3), in the box's frame, to the box of half sizes (3,)."""
    excess = np.abs(points) - half
    outside = np.linalg.norm(np.maximum(excess, 0.0), axis=-1)
    inside = np.minimum(excess.max(axis=-1), 0.0)
    return outside + inside


def _segment_box(a, b, box: BoxObstacle):
    rotation = box.rotation
    local_a = (a - box.center) @ rotation
    local_b = (b - box.center) @ rotation
    half = np.asarray(box.size, dtype=float) / 2.0
    lo, hi = np.zeros(a.shape[:-1]), np.ones(a.shape[:-1])
    ratio = (np.sqrt(5.0) - 1.0) / 2.0

    def at(t):
        return _box_signed(local_a + t[..., None] * (local_b - local_a), half)

    for _ in range(_GOLDEN_STEPS):
        c, d = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        left = at(c) < at(d)  # the minimum lies in [lo, d]
        hi, lo = np.where(left, d, hi), np.where(left, lo, c)
    return np.minimum.reduce([at((lo + hi) / 2.0), at(np.zeros_like(lo)), at(np.ones_like(lo))])


def _box_distance(a, b, radius, box: BoxObstacle, exact_below: float) -> np.ndarray:
    """Capsules to a box: exact where it may matter, a lower bound elsewhere. The box lies
    within its circumscribed ball, so the distance to the ball bounds the distance from below
    and the distance to the box's center from above; the exact search runs where the lower
    bound is under ``exact_below`` or under the smallest upper bound (where the minimum is)."""
    center = np.asarray(box.center, dtype=float)
    to_center = _point_segment(center, a, b) - radius
    lower = to_center - float(np.linalg.norm(box.size)) / 2.0
    threshold = max(exact_below, float(to_center.min()))
    exact = lower < threshold
    out = np.array(lower, dtype=float)
    if exact.any():
        radius = np.broadcast_to(radius, lower.shape)
        out[exact] = _segment_box(a[exact], b[exact], box) - radius[exact]
    return out


def capsule_distance(
    a: np.ndarray, b: np.ndarray, radius: np.ndarray, obstacle: Obstacle, exact_below: float = np.inf
) -> np.ndarray:
    """Signed distance (m) of the capsules (a, b, radius) to ``obstacle``; shape of ``radius``
    broadcast with a[..., 0]. Distances of boxes above ``exact_below`` (and above the smallest)
    may be lower bounds only: exact where they decide."""
    if isinstance(obstacle, SphereObstacle):
        center = np.asarray(obstacle.center, dtype=float)
        return _point_segment(center, a, b) - radius - obstacle.radius
    if isinstance(obstacle, CapsuleObstacle):
        return _segment_segment(a, b, np.asarray(obstacle.a, float), np.asarray(obstacle.b, float)) - radius - obstacle.radius
    if isinstance(obstacle, BoxObstacle):
        return _box_distance(a, b, radius, obstacle, exact_below)
    raise TypeError(f"unknown obstacle {obstacle!r}")
