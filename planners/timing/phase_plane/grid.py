"""The phase-plane method's grid as its compiled kernels read it (``toptraj.planners.timing.phase_plane.method``):
the constraint rows of each interval in its two discretizations (interpolation: every row held
at both ends of the interval; midpoint), the rows, bounds and first-order speed bound of one
grid as contiguous arrays, a solution on one grid, its interval times, and the intervals a
refined grid keeps whole."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from toptraj.planners.constraints.admissible_kernels import NOTHING_BEFORE, point_bounds
from toptraj.planners.constraints.path_constraints import LinearRows, PathConstraints


def interval_rows(s: np.ndarray, right: LinearRows, left: LinearRows) -> LinearRows:
    """Rows of each interval i (shape (N, 2m)) on its start state (u_i, x_i): every row at s_i,
    ``a_i u + b_i x_i + c_i``, and at s_i+1 as seen from the interval,
    ``a_i+1 u + b_i+1 (x_i + 2 ds u) + c_i+1`` (the interpolation discretization)."""
    ds = np.diff(s)[:, None]
    return LinearRows(
        a=np.hstack([right.a[:-1], left.a[1:] + 2.0 * ds * left.b[1:]]),
        b=np.hstack([right.b[:-1], left.b[1:]]),
        c=np.hstack([right.c[:-1], left.c[1:]]),
        lower=np.hstack([right.lower[:-1], right.lower[1:]]),
        upper=np.hstack([right.upper[:-1], right.upper[1:]]),
    )


def midpoint_stage_rows(s: np.ndarray, right: LinearRows, left: LinearRows) -> LinearRows:
    """Rows of each interval i (shape (N, m)) on its start state (u_i, x_i): every row taken at
    the interval's midpoint, ``a_m u + b_m (x_i + ds u) + c_m``, with the coefficients averaged
    from the two ends (the right-hand side of s_i, the left-hand side of s_i+1)."""
    ds = np.diff(s)[:, None]
    a_mid = 0.5 * (right.a[:-1] + left.a[1:])
    b_mid = 0.5 * (right.b[:-1] + left.b[1:])
    c_mid = 0.5 * (right.c[:-1] + left.c[1:])
    return LinearRows(
        a=a_mid + ds * b_mid,
        b=b_mid,
        c=c_mid,
        lower=right.lower[:-1],
        upper=right.upper[:-1],
    )


class KernelRows(NamedTuple):
    """The kernels' row arrays, each (N + 1, m): seen from the right, from the left, bounds."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    a_left: np.ndarray
    b_left: np.ndarray
    c_left: np.ndarray
    d_left: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


class Grid(NamedTuple):
    """The constraints on one grid as contiguous arrays for the kernels: s (N + 1,), the rows
    seen from the right and from the left (``a, b, c, d`` each (N + 1, m)), their bounds, the
    first-order bound x_bound = sd_max^2 (N + 1,), the joint whose velocity limit sets it (N + 1,,
    -1 where none or unknown), whether the rows are smooth through each grid point (N + 1,,
    ``toptraj.planners.constraints.torque_interpolation.smooth_points``) and whether any row has viscous friction."""

    constraints: PathConstraints
    s: np.ndarray
    rows: KernelRows
    x_bound: np.ndarray
    binding: np.ndarray
    smooth: np.ndarray
    friction: bool

    @classmethod
    def of(cls, constraints: PathConstraints) -> Grid:
        rows = KernelRows(*(
            np.ascontiguousarray(array, dtype=np.float64)
            for array in (
                constraints.a, constraints.b, constraints.c, constraints.d,
                constraints.a_left, constraints.b_left, constraints.c_left, constraints.d_left,
                constraints.lower, constraints.upper,
            )
        ))  # fmt: skip
        s = np.ascontiguousarray(constraints.s, dtype=np.float64)
        x_bound = np.ascontiguousarray(constraints.sd_max**2, dtype=np.float64)
        joint = constraints.velocity_joint
        binding = np.full(len(s), -1, dtype=np.int64) if joint is None else np.ascontiguousarray(joint, dtype=np.int64)
        return cls(constraints, s, rows, x_bound, binding, constraints.smooth, constraints.has_friction)

    def friction_reference(self) -> np.ndarray:
        """``toptraj.planners.constraints.admissible.friction_reference``: the maximum velocity curve without friction,
        capped by the first-order bound (1 where it is not positive and finite)."""
        a, b, c, _, _, _, _, _, lower, upper = self.rows
        x_max = point_bounds(a, b, c, lower, upper, self.x_bound)[4]
        return np.where(np.isfinite(x_max) & (x_max > 0), x_max, 1.0)


class Profile(NamedTuple):
    """A solution on one grid: x = sd^2 (N + 1,), which intervals the envelope capped (N,), the
    envelope (N + 1,), the admissible upper x_i of each interval (N,), how much faster each
    interval could be crossed at its bounds (N,, ``toptraj.planners.timing.phase_plane.refinement_kernels.switch_excess``)
    and the intervals' bounds (``toptraj.planners.constraints.admissible_kernels.interval_bounds``' p, q, r, x_low, x_high)."""

    x: np.ndarray
    capped: np.ndarray
    envelope: np.ndarray
    x_high: np.ndarray
    switch_excess: np.ndarray
    bounds: tuple = NOTHING_BEFORE


def interval_times(s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The time (s) of each interval of the grid ``s`` (n,) crossed at x = sd^2 (n,) given at its
    points: 2 ds / (sqrt(x_i) + sqrt(x_i+1)), exact for a constant acceleration."""
    root = np.sqrt(x)
    return 2.0 * np.diff(s) / np.maximum(root[:-1] + root[1:], 1e-300)


def kept_intervals(s: np.ndarray, coarser: np.ndarray) -> np.ndarray:
    """For each interval of the refined grid ``s`` (N + 1,), the interval of the grid
    ``coarser`` it refines that it keeps whole (the same two ends), or -1 (N,, int64)."""
    at = np.minimum(np.searchsorted(coarser, s[:-1]), len(coarser) - 2)
    whole = (coarser[at] == s[:-1]) & (coarser[at + 1] == s[1:])
    return np.where(whole, at, -1).astype(np.int64)
