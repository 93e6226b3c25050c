"""The dense states of a timing on its grid, in one compiled pass (numba): what
``TimeScaling.dense_states`` returns and the dense limit check reads. No knowledge of paths or
robots (``nogil``, cached)."""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit


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
