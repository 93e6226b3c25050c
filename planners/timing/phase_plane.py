"""``phase_plane``: time-optimal path timing by numerical integration in the (s, sd) phase plane.

The method of Bobrow, Dubowsky & Gibson, Shin & McKay and Pfeiffer & Johanni as Jeong & Lee
section 3 describe it: along the path the limits bound the path acceleration u = sdd between
alpha(s, x) and beta(s, x) (x = sd^2; Jeong & Lee eq. (3.6) solved for mu-dot), the optimal
profile accelerates at beta as long as it can and decelerates at alpha when it must, and it
touches the maximum velocity curve (MVC) only at switching points: tangent points, points where
the MVC jumps, and singular points where the u-coefficient of a binding row vanishes (zero
inertia).

The integration runs in its reachability form, which makes every switching point fall out of
two sweeps instead of a search:

1. Backward, from the end state, at maximum deceleration alpha, restarted from the MVC wherever
   the backward curve would cross it: the envelope K(s) of every maximum-deceleration curve
   that ends at the end state or leaves the MVC. Below K the end is reachable; above it, not.
2. Forward, from the start state, at maximum acceleration beta, capped by K.

Where the forward curve meets K it switches from acceleration to deceleration; where it leaves K
it starts accelerating from a point of the MVC or of a deceleration curve through one, which is
exactly a switching point of the classical method. At a singular point the admissible u-interval
collapses to one value and the sweeps take it: no chattering, no special case.

Discretization: on the grid s_0 < ... < s_N, u is constant per interval (x linear in s) and every
row holds at both ends of each interval (x_i+1 = x_i + 2 ds u), so the limits hold at every grid
point and, to second order, between them. Each sweep step is a closed-form minimum over the rows
(``planners.kernels``): no LP is solved anywhere. This constant-u scheme is conservative by a
first-order amount, so the grid is refined where it costs time: the midpoint discretization on
the same grid (second-order accurate, but not conservative) estimates the error of each interval,
and the worst intervals are split, with the constraint rows evaluated anew there, until the
estimated duration error is below the tolerance.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from planners.constraints import LinearRows, PathConstraints
from planners.deadline import NO_DEADLINE, Deadline
from planners.diagnostics import static_load
from planners.errors import InfeasiblePath
from planners.kernels import backward_envelope, forward_profile
from planners.mvc import acceleration_bounds, admissible_set, friction_reference
from planners.timing.base import AT_REST, Boundary, TimeScaling, TimingMethod

#: Relative slack when comparing x values computed along different routes.
_SLACK = 1e-9
#: Relative slack of a boundary speed above the reachable envelope. A time-optimal motion that
#: starts at a limit (the re-timing of a free path from a moving start) starts on the envelope,
#: which the discretization places a few 1e-7 lower; the first interval then absorbs the
#: difference, a relative change of its acceleration of that order.
_BOUNDARY_SLACK = 1e-5


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


class PhasePlaneMethod(TimingMethod):
    """Time-optimal timing by phase-plane integration (see the module docstring).

    Args:
        tolerance: Relative duration error at which grid refinement stops. The error is
            estimated by the midpoint discretization on the same grid (second order, so it
            stands for the exact answer); intervals where the two disagree most are split, with
            the constraint rows evaluated anew at the new points, until the estimate falls
            below ``tolerance`` or ``max_refinements`` rounds are done.
        max_refinements: Rounds of refinement; 0 keeps the given grid.
    """

    name = "phase_plane"

    def __init__(self, tolerance: float = 6e-4, max_refinements: int = 3):
        self.tolerance = tolerance
        self.max_refinements = max_refinements

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> TimeScaling:
        boundary = (boundary.sd_start**2, boundary.sd_end**2)
        for round_ in range(self.max_refinements + 1):
            profile = _solve_on_grid(constraints, boundary, deadline, interval_rows)
            if round_ == self.max_refinements or not constraints.can_refine:
                break
            split = self._intervals_to_split(constraints, profile, boundary, deadline)
            if split.size == 0:
                break
            deadline.check()
            constraints = constraints.with_points(0.5 * (constraints.s[split] + constraints.s[split + 1]))
        switches = _switch_points(constraints.s, profile)
        return TimeScaling(constraints.s, np.sqrt(profile.x), switches)

    def _intervals_to_split(self, constraints, profile, boundary, deadline) -> np.ndarray:
        """Intervals whose time the midpoint discretization (second order) finds different by
        more than their share of the tolerance, when the total difference exceeds the tolerance.
        Halving an interval quarters its (second-order local) excess, so this equidistributes
        the error over the grid."""
        try:
            reference = _solve_on_grid(constraints, boundary, deadline, midpoint_stage_rows, profile.x)
        except InfeasiblePath:
            return np.empty(0, dtype=int)
        # Where the two discretizations disagree, in either direction, the grid does not resolve
        # the profile: the midpoint scheme is no bound, and on coarse grids of strongly curved
        # paths it can come out longer than the conservative one.
        excess = np.abs(_interval_times(constraints.s, profile.x) - _interval_times(constraints.s, reference.x))
        budget = self.tolerance * _interval_times(constraints.s, reference.x).sum()
        if excess.sum() <= budget:
            return np.empty(0, dtype=int)
        return np.flatnonzero(excess > 0.5 * budget / len(excess))


class _Profile(NamedTuple):
    """A solution on one grid: x = sd^2 (N + 1,), which intervals the envelope capped (N,), the
    envelope (N + 1,), the interval rows and their admissible upper x (N,)."""

    x: np.ndarray
    capped: np.ndarray
    envelope: np.ndarray
    stage: LinearRows
    x_high: np.ndarray


def _interval_times(s: np.ndarray, x: np.ndarray) -> np.ndarray:
    root = np.sqrt(x)
    return 2.0 * np.diff(s) / np.maximum(root[:-1] + root[1:], 1e-300)


def _solve_on_grid(constraints, boundary, deadline, discretize, x_ref=None) -> _Profile:
    """Integrate on the constraints' own grid. Viscous friction is linearized around ``x_ref``
    (default: a first pass around ``friction_reference``, then one around its answer)."""
    x_bound = constraints.sd_max**2
    passes = 1
    if x_ref is None:
        x_ref = friction_reference(constraints)
        passes = 2 if constraints.has_friction else 1
    for _ in range(passes):
        stage = discretize(constraints.s, constraints.linearized(x_ref), constraints.linearized(x_ref, "left"))
        profile = _integrate(constraints, stage, x_bound, *boundary, deadline)
        x_ref = profile.x
    return profile


def _integrate(constraints, stage: LinearRows, x_bound, x_start, x_end, deadline) -> _Profile:
    ds = np.ascontiguousarray(np.diff(constraints.s))
    admissible = admissible_set(stage, x_bound[:-1])
    bounds = acceleration_bounds(stage)
    if x_end > x_bound[-1] * (1 + _SLACK) + _SLACK:
        raise InfeasiblePath(
            f"the end path speed {np.sqrt(x_end):.6g} 1/s is above the maximum velocity curve "
            f"({np.sqrt(x_bound[-1]):.6g} 1/s) at s = 1",
            s=1.0,
        )
    deadline.check()
    envelope, floor, failed = backward_envelope(
        ds, bounds.p, bounds.q, bounds.r, bounds.w, admissible.x_min, admissible.x_max, float(x_end), _SLACK
    )
    if failed >= 0:
        raise _stuck(constraints, admissible, stage, int(failed))
    if x_start < floor[0] * (1 - 1e-7) - 1e-12:
        clause, joint = static_load(constraints, 0)
        raise InfeasiblePath(
            f"the motion cannot start at path speed {np.sqrt(x_start):.6g} 1/s at s = 0: every "
            f"motion that can follow the path needs at least {np.sqrt(floor[0]):.6g} 1/s there{clause}",
            s=0.0,
            joint=joint,
        )
    if x_start > envelope[0] * (1 + _BOUNDARY_SLACK) + 1e-12:
        raise InfeasiblePath(
            f"the start path speed {np.sqrt(x_start):.6g} 1/s is above what the limits allow at s = 0 "
            f"({np.sqrt(max(envelope[0], 0.0)):.6g} 1/s: the maximum velocity curve or the fastest "
            "speed from which the rest of the path can still be followed)",
            s=0.0,
        )
    deadline.check()
    x, capped = forward_profile(ds, bounds.r, bounds.w, envelope, float(min(x_start, envelope[0])))
    x[0], x[-1] = x_start, x_end
    return _Profile(np.maximum(x, 0.0), capped, envelope, stage, admissible.x_max)


def _switch_points(s, profile: _Profile) -> tuple[tuple[float, str], ...]:
    """Where the profile changes between accelerating (at beta) and following the envelope."""
    capped, envelope, x_high, stage = profile.capped, profile.envelope, profile.x_high, profile.stage
    points = []
    scale = np.maximum(np.abs(stage.a) + np.abs(stage.b), 1e-300)
    for i in np.flatnonzero(np.diff(capped.astype(int)) != 0) + 1:
        if capped[i]:
            points.append((float(s[i]), "deceleration"))
            continue
        # Leaving the envelope: the touch point on (or the deceleration curve from) the MVC.
        on_mvc = envelope[i] >= x_high[min(i, len(x_high) - 1)] * (1 - 1e-6)
        if not on_mvc:
            points.append((float(s[i]), "acceleration"))
        elif np.any(np.abs(stage.a[min(i, len(x_high) - 1)]) <= 1e-6 * scale[min(i, len(x_high) - 1)]):
            points.append((float(s[i]), "singular"))
        elif i >= 1 and i + 1 < len(x_high) and abs(x_high[i + 1] - x_high[i - 1]) > 0.25 * max(x_high[i], 1e-12):
            points.append((float(s[i]), "discontinuity"))
        else:
            points.append((float(s[i]), "tangent"))
    return tuple(points)


def _stuck(constraints: PathConstraints, admissible, stage: LinearRows, i: int) -> InfeasiblePath:
    """No admissible state at interval ``i`` lets the motion reach the end: say where and why."""
    s = constraints.s
    if admissible.x_max[i] < admissible.x_min[i]:
        first, second = admissible.blocking_rows[i]
        what = constraints.describe_row(first)
        if second != first:
            what += f" and {constraints.describe_row(second)}"
        return InfeasiblePath(
            f"no motion along the path can meet the {what} between s = {s[i]:.4f} and "
            f"s = {s[i + 1]:.4f}, not even at rest",
            s=float(s[i]),
            joint=constraints.joint_names[constraints.rows[first % len(constraints.rows)][1]],
        )
    clause, joint = static_load(constraints, i + 1)
    return InfeasiblePath(
        f"no motion can follow the path from s = {s[i]:.4f} to its end: the limits cannot bring "
        f"the motion to the required speed by s = {s[i + 1]:.4f}{clause}",
        s=float(s[i]),
        joint=joint,
    )
