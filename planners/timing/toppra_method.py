"""``toppra``: the TOPP-RA package (Pham & Pham, "A New Approach to Time-Optimal Path
Parameterization Based on Reachability Analysis", IEEE T-RO 2018) on our ``PathConstraints``.

The adapter hands toppra the precomputed rows as one canonical linear constraint, so toppra never
re-derives dynamics; the rows are handed over in toppra's interpolation discretization (each
interval's u_i checked at s_i and, through x_i+1 = x_i + 2 ds_i u_i, at s_i+1, with the rows as
seen from that interval, which matters at the corners of a path), keeping the limits between grid
points. Its failure signals
(``None``, NaN controllable sets, return codes) become toptraj errors here.
"""

from __future__ import annotations

import logging

import numpy as np

from toptraj.planners.constraints.admissible import acceleration_bounds, admissible_set, friction_reference
from toptraj.planners.constraints.held_load import blocked_even_at_rest, holding_facts, static_load
from toptraj.planners.constraints.path_constraints import LinearRows, PathConstraints
from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import AT_REST, Boundary, TimeScaling, TimingMethod
from toptraj.planners.timing.friction import friction_passes

logging.getLogger("toppra").setLevel(logging.ERROR)

#: Stand-in for an unlimited bound: toppra's LP solver needs finite numbers.
_UNBOUNDED = 1e12


def _toppra_classes():
    """toppra's algorithm and constraint classes (imported lazily: the import costs ~0.3 s)."""
    import toppra.algorithm
    import toppra.constraint
    from toppra.interpolator import AbstractGeometricPath

    class GridPath(AbstractGeometricPath):
        """The path interval toppra asks for; the geometry itself lives in the constraint rows."""

        def __init__(self, s: np.ndarray):
            self._s = s

        @property
        def path_interval(self):
            return np.array([self._s[0], self._s[-1]])

        @property
        def dof(self):
            return 1

        @property
        def waypoints(self):
            return self._s

        def __call__(self, path_positions, order=0) -> np.ndarray:
            raise TimingFailed("toppra asked for path geometry, which the adapter does not hold")

    class PrecomputedRows(toppra.constraint.LinearConstraint):
        """Rows ``lower <= a u + b x + c <= upper`` and bounds ``x <= x_bound`` given as arrays,
        already in the interpolation discretization."""

        def __init__(self, right: LinearRows, x_bound: np.ndarray, left: LinearRows):
            super().__init__()
            self._right, self._left = right, left
            self._x_bound = x_bound

        def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
            right, left = self._right, self._left
            n_points, n_rows = right.a.shape
            xbound = np.column_stack([np.zeros(n_points), np.minimum(self._x_bound, _UNBOUNDED)])
            if n_rows == 0:
                return None, None, None, None, None, None, xbound
            delta = np.append(np.diff(gridpoints), 0.0)[:, None]
            # Interval i: rows at s_i on (u_i, x_i), and rows at s_i+1 on (u_i, x_i + 2 ds_i u_i).
            next_a = np.vstack([left.a[1:] + 2 * delta[:-1] * left.b[1:], right.a[-1:]])
            a = np.hstack([right.a, next_a])
            b = np.hstack([right.b, np.vstack([left.b[1:], right.b[-1:]])])
            c = np.hstack([right.c, np.vstack([left.c[1:], right.c[-1:]])])
            upper = np.hstack([right.upper, np.vstack([right.upper[1:], right.upper[-1:]])])
            lower = np.hstack([right.lower, np.vstack([right.lower[1:], right.lower[-1:]])])
            identity = np.eye(2 * n_rows)
            F = np.broadcast_to(np.vstack([identity, -identity]), (n_points, 4 * n_rows, 2 * n_rows))
            g = np.hstack([np.minimum(upper, _UNBOUNDED), np.minimum(-lower, _UNBOUNDED)])
            return a, b, c, F, g, None, xbound

    return toppra.algorithm.TOPPRA, PrecomputedRows, GridPath


class ToppraMethod(TimingMethod):
    """Time-optimal timing by TOPP-RA with toppra's Seidel LP solver."""

    name = "toppra"
    absolute_tolerances = True

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> TimeScaling:
        x_ref = friction_reference(constraints)
        if not constraints.has_friction:
            return _solved(constraints, x_ref, boundary, deadline)
        # Viscous friction, its tangent moved onto the answer (``toptraj.planners.timing.friction``).
        return friction_passes(
            lambda reference: _solved(constraints, reference, boundary, deadline), x_ref,
            lambda scaling: scaling.sd**2, lambda scaling: scaling.duration, passes=1,
        )


def _solved(constraints: PathConstraints, x_ref: np.ndarray, boundary: Boundary, deadline: Deadline) -> TimeScaling:
    """toppra's timing of ``constraints``, viscous friction linearized around ``x_ref`` (N + 1,)."""
    TOPPRA, PrecomputedRows, GridPath = _toppra_classes()
    sd_start, sd_end = boundary.sd_start, boundary.sd_end
    x_bound = constraints.sd_max**2
    rows = constraints.linearized(x_ref).normalized()
    left_rows = constraints.linearized(x_ref, side="left").normalized()
    deadline.check()
    instance = TOPPRA(
        [PrecomputedRows(*_singular_rows_as_bounds(rows, x_bound), left_rows)],
        GridPath(constraints.s),
        gridpoints=constraints.s,
        solver_wrapper="seidel",
    )
    sdd, sd, _, K = instance.compute_parameterization(sd_start, sd_end, return_data=True)
    if sd is None:
        raise _explain_failure(constraints, rows, x_bound, K, sd_start, sd_end)
    return TimeScaling(constraints.s, np.asarray(sd, dtype=float))


def _singular_rows_as_bounds(rows: LinearRows, x_bound: np.ndarray) -> tuple[LinearRows, np.ndarray]:
    """Rows whose u-coefficient vanishes at a grid point (a zero-inertia point, e.g. where a
    circular blend meets a straight segment) bound x = sd^2 alone there: folded into the
    first-order bound and dropped from the rows at that point. Kept as rows, such a bound is
    parallel to toppra's objective (the largest x), and its LP solver returns NaN on that tie.
    Rows that bound x from below are kept."""
    bounds = acceleration_bounds(rows)
    with np.errstate(invalid="ignore", divide="ignore"):
        cut_high = np.where(rows.b > 0, (rows.upper - rows.c) / rows.b, (rows.lower - rows.c) / rows.b)
        cut_low = np.where(rows.b > 0, (rows.lower - rows.c) / rows.b, (rows.upper - rows.c) / rows.b)
    fold = bounds.singular & (rows.b != 0.0) & ~(cut_low > 0.0)
    if not fold.any():
        return rows, x_bound
    x_bound = np.minimum(x_bound, np.where(fold, cut_high, np.inf).min(axis=1))

    def kept(array):
        return np.where(fold, 0.0, array)

    return LinearRows(kept(rows.a), kept(rows.b), kept(rows.c), rows.lower, rows.upper), x_bound


def _explain_failure(constraints, rows, x_bound, K, sd_start, sd_end) -> Exception:
    """Turn toppra's failure into an error that says where along the path it fails."""
    admissible = admissible_set(rows, x_bound)
    empty = np.flatnonzero(admissible.x_max < admissible.x_min)
    if empty.size:
        point = int(empty[0])
        where = f"at s = {constraints.s[point]:.4f} (grid point {point} of {len(constraints.s) - 1})"
        return blocked_even_at_rest(constraints, admissible.blocking_rows, empty, point, where)
    if sd_start**2 > admissible.x_max[0] or sd_end**2 > admissible.x_max[-1]:
        return InfeasiblePath(
            f"the boundary path speeds ({sd_start}, {sd_end}) 1/s exceed the maximum velocity curve "
            f"({admissible.sd_max[0]:.6g}, {admissible.sd_max[-1]:.6g}) 1/s"
        )
    if K is not None and np.isnan(K).any():
        return _uncontrollable(constraints, np.flatnonzero(np.isnan(K).any(axis=1)).max())
    if K is not None and not K[0, 0] <= sd_start**2 + 1e-9:
        held, joint, limit = static_load(constraints, 0)
        return InfeasiblePath(
            f"the motion cannot start at path speed {sd_start:g} 1/s at s = 0: every admissible "
            f"motion there needs sd >= {np.sqrt(K[0, 0]):.4g} 1/s",
            s=0.0,
            joint=joint,
            limit=limit,
            held=held,
            **holding_facts(constraints),
        )
    return TimingFailed("toppra failed to parameterize the path")


def _uncontrollable(constraints: PathConstraints, last_bad: int) -> InfeasiblePath:
    """From grid point ``last_bad`` backwards no motion reaches the end of the path at the
    required speed: say where, and which joint cannot hold its load there."""
    where = min(last_bad + 1, len(constraints.s) - 1)
    held, joint, limit = static_load(constraints, where)
    return InfeasiblePath(
        f"no motion can follow the path from s = {constraints.s[last_bad]:.4f} to its end: the "
        f"limits cannot bring the motion to the required speed by s = {constraints.s[where]:.4f}",
        s=float(constraints.s[last_bad]),
        joint=joint,
        limit=limit,
        held=held,
        **holding_facts(constraints),
    )
