"""Compiled passes of the dense limit check (numba): the dense states of a timing on a grid, and
|value| / limit of every state and joint, reduced in one sweep to what ``planners.limit_check``
reports (the peak per joint, the worst state, the states beyond a threshold). No knowledge of
paths or robots (``nogil``, cached)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, error_model="numpy")
def utilization_pass(value, limit, threshold, peak, over):  # pragma: no cover - compiled
    """For ``value`` (n, k) against ``limit`` (k,): write the largest |value| / limit of each
    column into ``peak`` (k,), set ``over[i]`` (n,) where a state's ratio exceeds ``threshold``
    (leaving it set where it was) and return (ratio, state, column) of the largest one.

    A ratio that is not a number (an infinite value against an infinite limit, 0 against 0)
    counts as 0; a column without limit (inf) has ratio 0; a nonzero value against a zero
    limit, or an infinite one against a finite limit, is inf.
    """
    n, k = value.shape
    for j in range(k):
        peak[j] = 0.0
    worst, worst_state, worst_column = -1.0, 0, 0
    for i in range(n):
        state = 0.0
        column = 0
        for j in range(k):
            ratio = abs(value[i, j]) / limit[j]
            if ratio != ratio:
                ratio = 0.0
            if ratio > peak[j]:
                peak[j] = ratio
            if ratio > state or j == 0:
                state = ratio
                column = j
        if state > threshold:
            over[i] = True
        if state > worst:
            worst, worst_state, worst_column = state, i, column
    return worst, worst_state, worst_column


@njit(cache=True, nogil=True)
def grid_states(s, sd, sdd, reference, points):  # pragma: no cover - compiled
    """The dense states of a timing on the grid ``s`` (K + 1,) with path speeds ``sd`` (K + 1,)
    and the path acceleration ``sdd`` (K,) of each interval (x = sd^2 linear in s within it):
    ``points`` (>= 2) states per interval of ``reference`` (a grid of which ``s`` is a
    refinement; empty: ``s`` itself), both ends of each interval of ``s`` included, evenly
    spaced in s within it. An interval of ``s`` gets ``ceil((points - 1) w / w_ref)`` parts,
    at least one (w its width, w_ref that of the interval of ``reference`` holding its middle).

    Returns s, sd, sdd (n,), left (n,: the state ends its interval) and interval (n,).
    """
    n_intervals = s.shape[0] - 1
    base = points - 1
    parts = np.empty(n_intervals, dtype=np.int64)
    n_reference = reference.shape[0]
    k = 0
    for i in range(n_intervals):
        if n_reference < 2:
            parts[i] = base
            continue
        middle = 0.5 * (s[i] + s[i + 1])
        while k < n_reference and reference[k] < middle:
            k += 1
        holder = min(max(k - 1, 0), n_reference - 2)
        room = reference[holder + 1] - reference[holder]
        parts[i] = max(np.ceil(base * (s[i + 1] - s[i]) / room - 1e-9), 1.0)
    total = 0
    for i in range(n_intervals):
        total += parts[i] + 1
    out_s = np.empty(total)
    out_sd = np.empty(total)
    out_sdd = np.empty(total)
    left = np.empty(total, dtype=np.bool_)
    interval = np.empty(total, dtype=np.int64)
    state = 0
    for i in range(n_intervals):
        s0, s1 = s[i], s[i + 1]
        x0 = sd[i] * sd[i]
        x1 = sd[i + 1] * sd[i + 1]
        for step in range(parts[i] + 1):
            fraction = step / parts[i]
            out_s[state] = s0 + fraction * (s1 - s0)
            out_sd[state] = np.sqrt(max(x0 + fraction * (x1 - x0), 0.0))
            out_sdd[state] = sdd[i]
            left[state] = step == parts[i]
            interval[state] = i
            state += 1
    return out_s, out_sd, out_sdd, left, interval
