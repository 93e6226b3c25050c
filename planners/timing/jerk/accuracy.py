"""How far the jerk-limited timing's grid solution lies from the optimum of its continuous
problem, estimated on a second grid (``toptraj.planners.timing.jerk.method``).

The grid solution converges to the optimum as the grid is refined; the difference between the
durations on two nested grids, T_coarse - T_fine, estimates the fine grid's error from above
wherever the error shrinks at least linearly with the interval (T_coarse - T* = 2 (T_fine - T*)
for first order, 4 times for second). The coarse grid is every other point of the fine one (the
points toward an end at rest, which resolve its constant-jerk phase, and the path's knots all
kept), so that the two solves share nothing but the problem.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints


def coarser(constraints: PathConstraints, original: np.ndarray) -> PathConstraints | None:
    """``constraints`` on every other point of their grid, the ends, the points inside the first
    and last interval of the ``original`` grid (the graded points toward an end at rest) and
    the path's knots kept; ``None`` when that drops no point or leaves fewer than six."""
    s = constraints.s
    keep = np.zeros(len(s), dtype=bool)
    keep[::2] = True
    keep[[0, -1]] = True
    if len(original) > 2:
        keep |= (s <= original[1]) | (s >= original[-2])
    if constraints.knots is not None and len(constraints.knots):
        keep |= np.isin(s, constraints.knots)
    if keep.all() or keep.sum() < 6:
        return None

    def take(array):
        return None if array is None else np.asarray(array)[keep]

    same = constraints.a_left is constraints.a and constraints.b_left is constraints.b
    right = {name: take(getattr(constraints, name)) for name in ("a", "b", "c", "d")}
    left = (
        {f"{name}_left": right[name] for name in ("a", "b", "c", "d")}
        if same
        else {f"{name}_left": take(getattr(constraints, f"{name}_left")) for name in ("a", "b", "c", "d")}
    )
    jerk = None if constraints.jerk is None else (*(take(array) for array in constraints.jerk[:3]), constraints.jerk[3])
    jerk_left = None if constraints.jerk_left is None else tuple(take(array) for array in constraints.jerk_left)
    return dataclasses.replace(
        constraints,
        s=take(s),
        sd_max=take(constraints.sd_max),
        **right,
        **left,
        lower=take(constraints.lower),
        upper=take(constraints.upper),
        velocity_joint=take(constraints.velocity_joint),
        tool_bound=take(constraints.tool_bound),
        jerk=jerk,
        jerk_left=jerk_left,
        q=take(constraints.q),
    )


def relative_gap(coarse_duration: float, fine_duration: float) -> float:
    """(T_coarse - T_fine) / T_fine, at least 0: the estimated relative error of the fine grid's
    duration (module docstring)."""
    return max(0.0, (coarse_duration - fine_duration) / fine_duration)
