"""Compiled splitting of grid intervals for the phase-plane refinement (numba): the whole pieces
per interval that bring a summed error to a target with the fewest in all (``_pieces``, which
``toptraj.planners.timing.phase_plane.refinement_kernels.refinement`` asks), and the points that split the intervals so
(``split_points``). No knowledge of paths or robots (``nogil``, cached on disk).
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit


@njit(cache=True, nogil=True, inline="always")
def _gain(first, second, k):  # pragma: no cover - compiled
    """How much an interval's error ``first / k + second / k^2`` falls from k to k + 1 pieces."""
    return first * (1.0 / k - 1.0 / (k + 1.0)) + second * (1.0 / (k * k) - 1.0 / ((k + 1.0) * (k + 1.0)))


@njit(cache=True, nogil=True, inline="always")
def _continuous_pieces(error, order, shrink, pieces):  # pragma: no cover - compiled
    """Raise ``pieces`` (N,) to the real pieces per interval that bring the sum of ``error``
    (N,), each part falling as k^-order, to ``shrink`` times itself with the fewest pieces in
    all (Lagrange multipliers: k_i = e_i^(1 / (order + 1)) (sum_j e_j^(1 / (order + 1)) /
    (shrink sum_j e_j))^(1 / order))."""
    total = 0.0
    weights = 0.0
    for i in range(error.shape[0]):
        total += error[i]
        weights += error[i] ** (1.0 / (order + 1.0))
    if not total > 0.0:
        return
    scale = (weights / (shrink * total)) ** (1.0 / order)
    for i in range(error.shape[0]):
        wanted = error[i] ** (1.0 / (order + 1.0)) * scale
        if wanted > pieces[i]:
            pieces[i] = wanted


@njit(cache=True, nogil=True, inline="always")
def _sift_down(heap, key, size, position):  # pragma: no cover - compiled
    """Restore the max-heap ``heap[:size]`` (indices into ``key``) below ``position``."""
    item = heap[position]
    value = key[item]
    while True:
        child = 2 * position + 1
        if child >= size:
            break
        if child + 1 < size and key[heap[child + 1]] > key[heap[child]]:
            child += 1
        if key[heap[child]] <= value:
            break
        heap[position] = heap[child]
        position = child
    heap[position] = item


@njit(cache=True, nogil=True)
def _pieces(first, second, shrink, max_pieces, room, pieces):  # pragma: no cover - compiled
    """Set ``pieces`` (N,) to whole pieces per interval that bring the sum of the errors
    ``first / k + second / k^2`` (each (N,)) to ``shrink`` times its value at k = 1 with the
    fewest pieces in all, each interval at most at its cap: the real pieces that bring each part
    there on its own (``_continuous_pieces``, the larger of the two) rounded up, and at most
    ``max_pieces``. Those caps reach the target unless ``max_pieces`` cuts them; then the
    intervals take their caps, the real allocation's shares of a grid that one round cannot
    make fine enough. Within the caps the sum is separable and convex in each k, so adding one
    piece at a time where it removes the most error is optimal (a binary max-heap of each
    interval's next gain), also for the least error with at most ``room`` new pieces, where the
    grid's cap stops the adding first."""
    n_stages = first.shape[0]
    cap = np.ones(n_stages)
    _continuous_pieces(first, 1.0, shrink, cap)
    _continuous_pieces(second, 2.0, shrink, cap)
    total = 0.0
    at_caps = 0.0
    capped = 0.0
    key = np.empty(n_stages)
    heap = np.empty(n_stages, dtype=np.int64)
    size = 0
    for i in range(n_stages):
        total += first[i] + second[i]
        cap[i] = min(np.ceil(cap[i]), max_pieces)
        at_caps += first[i] / cap[i] + second[i] / (cap[i] * cap[i])
        capped += cap[i] - 1.0
        pieces[i] = 1.0
        key[i] = _gain(first[i], second[i], 1.0)
        if key[i] > 0.0 and cap[i] > 1.0:
            heap[size] = i
            size += 1
    target = shrink * total
    if at_caps > target and capped <= room:
        # Out of reach within the caps: every piece below them goes in.
        for i in range(n_stages):
            pieces[i] = cap[i]
        return
    for position in range(size // 2 - 1, -1, -1):
        _sift_down(heap, key, size, position)
    added = 0
    while total > target and size > 0 and added < room:
        i = heap[0]
        total -= key[i]
        pieces[i] += 1.0
        added += 1
        if pieces[i] < cap[i]:
            key[i] = _gain(first[i], second[i], pieces[i])
        else:
            size -= 1
            heap[0] = heap[size]
        if size > 0:
            _sift_down(heap, key, size, 0)


@njit(cache=True, nogil=True)
def split_points(s, wanted, priority, max_pieces, room):  # pragma: no cover - compiled
    """The points that split each interval of the grid s (N + 1,) into ceil(``wanted``) (N,)
    equal pieces, at most ``max_pieces`` per interval and ``room`` new points in all (the
    intervals of the highest ``priority`` (N,) first, each as asked); sorted, each strictly
    inside its interval, none closer than rounding resolves."""
    n_stages = s.shape[0] - 1
    pieces = np.empty(n_stages, dtype=np.int64)
    added = 0
    for i in range(n_stages):
        k = np.ceil(wanted[i])
        pieces[i] = max_pieces if k > max_pieces else int(k)
        if (s[i + 1] - s[i]) / pieces[i] < 1e-12:
            pieces[i] = 1  # no pieces shorter than rounding resolves
        added += pieces[i] - 1
    if added > room:
        # Too many for the grid's cap: the worst intervals first, each as asked.
        worst = np.argsort(-priority, kind="mergesort")
        used = 0
        for index in worst:
            if used + pieces[index] - 1 <= room:
                used += pieces[index] - 1
            else:
                pieces[index] = 1
        added = used
    points = np.empty(added)
    at = 0
    for i in range(n_stages):
        for j in range(1, pieces[i]):
            points[at] = s[i] + (s[i + 1] - s[i]) * j / pieces[i]
            at += 1
    return points
