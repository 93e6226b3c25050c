"""Compiled pass of the dense limit check (numba): |value| / limit of every state and joint,
reduced in one sweep to what ``toptraj.planners.checks.limit_check`` reports (the peak per joint, the worst
state, the states beyond a threshold). No knowledge of paths or robots (``nogil``, cached)."""

from __future__ import annotations

from toptraj.compiled import njit


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
