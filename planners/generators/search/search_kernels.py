"""The compiled inner loop of the branch and bound (``toptraj.planners.generators.search.branch_and_bound``):
best-first over subsets of grid paths with the tests t1, t2, t3 of Jeong & Lee section 2.4
(eqs. 2.6 to 2.8), in flat arrays instead of Python objects.

A subset is a row of the node table: ints ``(state, edge, parent, piece, complete)`` (shape
(N, 5)) and floats ``(g1, g2, g3, x, t3, t4)`` (shape (N, 6), seconds and 1/s^2; t4 ``nan``
until timed). Row 0 is the root (the start point, no move). The queue is a binary heap of
(key, order, node), ordered by key then by order of insertion, which is the order of
``heapq`` on ``(key, count, node)`` tuples: the same subsets are expanded in the same order
as the pure-Python loop it replaces, and the same grid paths found.

``run_chunk`` pops until one of: a complete grid path needs its t4 (the phase-plane method,
called from Python: ``settle_t4`` then queues it), a timed grid path is popped (found), the
expansions reach their most, the queue is empty or above t_u, or ``budget`` pops are done (the
caller checks its deadline between chunks). Arrays full: it returns before popping and the
caller grows them.

The loop test (no grid point twice) walks the node's chain of parents, at most the path's
length, instead of carrying a set of visited points per subset.
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.generators.search.bounds import forward_time, path_time

# node columns
STATE, EDGE, PARENT, PIECE, COMPLETE = 0, 1, 2, 3, 4
G1, G2, G3, X, T3, T4 = 0, 1, 2, 3, 4, 5
# counters
NODES, HEAP, ORDER, EXPANDED, GENERATED, PRUNED_T1, PRUNED_T2, PRUNED_T3, PRUNED_T4, PRUNED_TU = range(10)
# what ``run_chunk`` stopped at
DONE, NEED_T4, FOUND, MAX_EXPANSIONS, CHUNK, FULL = range(6)


@njit(cache=True, nogil=True)
def _less(key, order, i, j):  # pragma: no cover - compiled
    return key[i] < key[j] or (key[i] == key[j] and order[i] < order[j])


@njit(cache=True, nogil=True)
def _swap(key, order, node, i, j):  # pragma: no cover - compiled
    key[i], key[j] = key[j], key[i]
    order[i], order[j] = order[j], order[i]
    node[i], node[j] = node[j], node[i]


@njit(cache=True, nogil=True)
def push(key, order, node, counters, value, index):  # pragma: no cover - compiled
    """Queue node ``index`` with key ``value`` (sift up)."""
    i = counters[HEAP]
    key[i], order[i], node[i] = value, counters[ORDER], index
    counters[ORDER] += 1
    counters[HEAP] += 1
    while i > 0:
        up = (i - 1) // 2
        if not _less(key, order, i, up):
            break
        _swap(key, order, node, i, up)
        i = up


@njit(cache=True, nogil=True)
def _pop(key, order, node, counters):  # pragma: no cover - compiled
    """The least (key, node) of the heap, removed (sift down)."""
    top_key, top = key[0], node[0]
    n = counters[HEAP] - 1
    counters[HEAP] = n
    key[0], order[0], node[0] = key[n], order[n], node[n]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= n:
            break
        least = left
        if left + 1 < n and _less(key, order, left + 1, left):
            least = left + 1
        if not _less(key, order, least, i):
            break
        _swap(key, order, node, i, least)
        i = least
    return top_key, top


@njit(cache=True, nogil=True)
def _above(value, t_u, slack):  # pragma: no cover - compiled
    return not value <= t_u * (1.0 + slack)


@njit(cache=True, nogil=True)
def _visited(ints, index, point, edge_to, start):  # pragma: no cover - compiled
    """Whether the partial path ending at node ``index`` passes through grid point ``point``."""
    if point == start:
        return True
    while index >= 0:
        edge = ints[index, EDGE]
        if edge >= 0 and edge_to[edge] == point:
            return True
        index = ints[index, PARENT]
    return False


@njit(cache=True, nogil=True)
def _new(ints, floats, counters, state, edge, parent, piece, complete, g1, g2, g3, x):  # pragma: no cover - compiled
    i = counters[NODES]
    counters[NODES] += 1
    ints[i, STATE], ints[i, EDGE], ints[i, PARENT], ints[i, PIECE], ints[i, COMPLETE] = state, edge, parent, piece, complete
    floats[i, G1], floats[i, G2], floats[i, G3], floats[i, X] = g1, g2, g3, x
    floats[i, T3], floats[i, T4] = np.nan, np.nan
    return i


@njit(cache=True, nogil=True)
def chain_intervals(ints, index, first):  # pragma: no cover - compiled
    """The intervals (indices into the pieces' interval arrays, in order) of the pieces of the
    path ending at node ``index``."""
    total, k = 0, index
    while k >= 0:
        piece = ints[k, PIECE]
        if piece >= 0:
            total += first[piece + 1] - first[piece]
        k = ints[k, PARENT]
    out = np.empty(total, dtype=np.int64)
    end, k = total, index
    while k >= 0:
        piece = ints[k, PIECE]
        if piece >= 0:
            count = first[piece + 1] - first[piece]
            for j in range(count):
                out[end - count + j] = first[piece] + j
            end -= count
        k = ints[k, PARENT]
    return out


@njit(cache=True, nogil=True)
def child(ints, floats, key, order, node, counters, upper, slack, parent, state, edge, piece, ending, parent_key,
          t1, t2, h1, h2, first, ds, p, q, r, cap_start, cap_end):  # pragma: no cover - compiled
    """Make the subset ``parent`` + ``edge`` (fixing ``piece``; completing the path with the
    last span ``ending`` where >= 0), test it by t1, t2, t3 against t_u = ``upper[0]``, queue it."""
    counters[GENERATED] += 1
    t_u = upper[0]
    g1 = floats[parent, G1] + (t1[piece] if piece >= 0 else 0.0)
    g2 = floats[parent, G2] + (t2[piece] if piece >= 0 else 0.0)
    complete = ending >= 0
    if complete:
        f1, f2 = g1 + t1[ending], g2 + t2[ending]
    else:
        f1, f2 = g1 + h1[state], g2 + h2[state]
    f1 = max(f1, parent_key)
    if _above(f1, t_u, slack):
        counters[PRUNED_T1] += 1
        return
    f2 = max(f2, f1)
    if _above(f2, t_u, slack):
        counters[PRUNED_T2] += 1
        return
    g3, x = floats[parent, G3], floats[parent, X]
    if piece >= 0:
        span, x = forward_time(first[piece], first[piece + 1], ds, q, r, cap_start, cap_end, x)
        g3 += span
    mark = counters[NODES]
    made = _new(ints, floats, counters, state, edge, parent, piece, 0, g1, g2, g3, x)
    if complete:
        made = _new(ints, floats, counters, state, -1, made, ending, 1, f1, f2, g3, x)
        t3 = path_time(chain_intervals(ints, made, first), ds, p, q, r, cap_start, cap_end)
        floats[made, T3] = t3
        f3 = max(f2, t3)
    else:
        f3 = max(f2, g3 + h2[state])
    if _above(f3, t_u, slack):
        counters[PRUNED_T3] += 1
        counters[NODES] = mark  # the rows are free again
        return
    push(key, order, node, counters, f3, made)


@njit(cache=True, nogil=True)
def run_chunk(ints, floats, key, order, node, counters, upper, slack, budget, max_expansions, room, out_key,
              successor_ptr, successor_state, successor_piece, successor_ending, turn_out, edge_to, start,
              t1, t2, h1, h2, first, ds, p, q, r, cap_start, cap_end):  # pragma: no cover - compiled
    """Pop and expand up to ``budget`` subsets (module docstring); returns (what stopped it,
    the node concerned or -1), with the popped key of that node in ``out_key[0]``. ``room``:
    rows one expansion may add (to the node table and to the heap)."""
    pops = 0
    while counters[HEAP] > 0 and pops < budget:
        if counters[NODES] + room > ints.shape[0] or counters[HEAP] + room > key.shape[0]:
            return FULL, -1
        value, index = _pop(key, order, node, counters)
        out_key[0] = value
        if _above(value, upper[0], slack):
            counters[PRUNED_TU] += 1 + counters[HEAP]
            counters[HEAP] = 0
            return DONE, -1
        pops += 1
        if ints[index, COMPLETE] == 1:
            if np.isnan(floats[index, T4]):
                return NEED_T4, index
            return FOUND, index
        if counters[EXPANDED] >= max_expansions:
            return MAX_EXPANSIONS, index
        counters[EXPANDED] += 1
        state = ints[index, STATE]
        for k in range(successor_ptr[state], successor_ptr[state + 1]):
            after = successor_state[k]
            edge = turn_out[after]
            if _visited(ints, index, edge_to[edge], edge_to, start):
                continue  # a loop
            child(ints, floats, key, order, node, counters, upper, slack, index, after, edge, successor_piece[k],
                  successor_ending[k], value, t1, t2, h1, h2, first, ds, p, q, r, cap_start, cap_end)
    return (DONE if counters[HEAP] == 0 else CHUNK), -1


@njit(cache=True, nogil=True)
def settle_t4(ints, floats, key, order, node, counters, upper, slack, upper_margin, index, value, t4):  # pragma: no cover - compiled
    """Node ``index`` (complete, popped at key ``value``) timed at ``t4``: discarded above t_u,
    else t_u lowered to (1 + epsilon) t4 and the node queued again at max(value, t4)."""
    floats[index, T4] = t4
    if _above(t4, upper[0], slack):
        counters[PRUNED_T4] += 1
        return
    upper[0] = min(upper[0], (1.0 + upper_margin) * t4)
    push(key, order, node, counters, max(value, t4), index)
