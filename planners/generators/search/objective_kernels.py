"""The local optimization's objective J(P) (``toptraj.planners.generators.search.local``) in one
compiled call: from the interior control points to the midpoint duration plus the penalties,
the same computation as the reference path (``BSplinePath``, ``build_path_constraints``,
``midpoint_duration``, ``free_distances``) without building any of its objects.

The spline's power-basis coefficients on each knot interval are those of ``BSplinePath``, to
the last bit: at an interval's left end only four B-spline basis functions are nonzero (de
Boor, *A Practical Guide to Splines*, 2001, ch. IX), so q^(nu) there is the sum of four control
points times those functions' nu-th derivatives, which SciPy computes once per round of the
optimization (``basis_weights``: the knots change only between rounds) and the kernel sums in
SciPy's order (``power_coefficients``); ``paths.waypoints.cubic_pieces`` evaluates them as
``BSplinePath`` does. The rows are then written by the same kernels as
``build_path_constraints`` (``robots.chain_dynamics.rnea_sets``, ``assembly_kernels``), swept by
the phase-plane kernels as ``midpoint_duration`` sweeps them (the interpolation pass, twice with
viscous friction, then the midpoint pass; without friction, of the interpolation pass only
the backward sweep, which decides whether it fails; never the switching excesses, which only
an exact timing's refinement reads), and the distance lower bound of the penalty comes
from ``distance_kernels`` as in ``free_space.point_distances`` (a box's or a pair's exact
distance computed only where a bound says it may lower the least, the same least to the
bit). The answers equal the reference
path's to rounding: the same inputs reach the same kernels (tests/planners/generators/test_search_objective.py).

Shapes: control points (k, n_dof); grid N + 1 points; obstacle samples S + 1 points; m rows.
"""

from __future__ import annotations

import numpy as np

from toptraj.compiled import njit
from toptraj.planners.constraints.admissible_kernels import interval_bounds, point_bounds
from toptraj.planners.constraints.assembly_kernels import assemble_rows, velocity_bound
from toptraj.planners.generators.search.distance_kernels import capsule_ends, lower_distances, pair_minimum
from toptraj.planners.paths.bspline import DEGREE, clamped_knots
from toptraj.planners.paths.waypoints import cubic_pieces
from toptraj.planners.timing.phase_plane.sweep_kernels import backward_envelope, forward_profile
from toptraj.robots.chain_dynamics import rnea_sets


def basis_weights(interior: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct knots (pieces + 1,) of the clamped cubic with the ``interior`` knots and,
    at the left end of each piece, the values and first three derivatives of the four basis
    functions nonzero there, (4, pieces, 4): the weights of ``power_coefficients``. They are
    SciPy's own (``BSpline`` on the identity), so the coefficients come out as
    ``BSplinePath`` computes them, to the last bit."""
    from scipy.interpolate import BSpline  # here: the searches' paths only

    interior = np.asarray(interior, dtype=float)
    knots = clamped_knots(interior)
    count = len(knots) - DEGREE - 1
    left = np.concatenate([[0.0], interior])
    basis = BSpline(knots, np.eye(count), DEGREE)
    columns = np.arange(len(left))[:, None] + np.arange(DEGREE + 1)[None, :]
    weights = np.stack([np.take_along_axis(basis(left, nu), columns, axis=1) for nu in range(DEGREE + 1)])
    return np.concatenate([left, [1.0]]), np.ascontiguousarray(weights)


@njit(cache=True, nogil=True)
def power_coefficients(control, weights):  # pragma: no cover - compiled
    """``BSplinePath``'s power-basis coefficients (4, pieces, n_dof) of the spline of
    ``control`` (k, n_dof): d3q/6, d2q/2, dq and q at each piece's left end, each the sum
    over the four nonzero basis functions in SciPy's order (``basis_weights``)."""
    pieces, dof = weights.shape[1], control.shape[1]
    out = np.empty((4, pieces, dof))
    for nu in range(4):
        scale = 6.0 if nu == 3 else (2.0 if nu == 2 else 1.0)
        for i in range(pieces):
            for j in range(dof):
                total = 0.0
                for r in range(4):
                    total += control[i + r, j] * weights[nu, i, r]
                out[3 - nu, i, j] = total / scale if nu >= 2 else total
    return out


@njit(cache=True, nogil=True)
def _envelope(s, rows, x_bound, x_ref, friction, midpoint, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """The first half of ``phase_plane.method._integrate`` at rest at both ends (``sweeps``'
    interval bounds and backward sweep, then ``_integrate``'s checks): ds (N,), q, r (N, k),
    the envelope (N + 1,), and whether the checks pass (else the path cannot be timed)."""
    a, b, c, d, lower, upper = rows
    ds = np.empty(s.shape[0] - 1)
    for i in range(ds.shape[0]):
        ds[i] = s[i + 1] - s[i]
    p, q, r, x_low, x_high, _ = interval_bounds(s, a, b, c, d, a, b, c, d, lower, upper, x_bound, x_ref, friction, midpoint, kept, before)
    if 0.0 > x_bound[-1] * (1 + slack) + slack:
        return ds, q, r, x_high, False
    envelope, floor, failed = backward_envelope(ds, p, q, r, x_low, x_high, 0.0, slack)
    holds = failed < 0 and not 0.0 < floor[0] * (1 - 1e-7) - 1e-12 and not 0.0 > envelope[0] * (1 + boundary_slack) + 1e-12
    return ds, q, r, envelope, holds


@njit(cache=True, nogil=True)
def _solved(s, rows, x_bound, x_ref, friction, midpoint, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """``phase_plane.method._integrate`` at rest at both ends: x (N + 1,), or an empty array
    where it raises (the path cannot be timed). ``sweeps`` but for its ``switch_excess``, which
    only the refinement of an exact timing reads."""
    ds, q, r, envelope, holds = _envelope(s, rows, x_bound, x_ref, friction, midpoint, slack, boundary_slack, kept, before)
    if not holds:
        return np.empty(0)
    x, _ = forward_profile(ds, r, q, envelope, min(0.0, envelope[0]))
    x[0], x[-1] = 0.0, 0.0
    for i in range(x.shape[0]):
        if x[i] < 0.0:
            x[i] = 0.0
    return x


@njit(cache=True, nogil=True)
def _midpoint_duration(s, rows, x_bound, friction, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """``phase_plane.method.midpoint_duration`` at rest (s), or -1 where no timing follows."""
    a, b, c, _, lower, upper = rows
    x_ref = x_bound
    if friction:
        x_max = point_bounds(a, b, c, lower, upper, x_bound)[4]
        x_ref = np.empty(x_max.shape[0])
        for i in range(x_max.shape[0]):
            x_ref[i] = x_max[i] if np.isfinite(x_max[i]) and x_max[i] > 0 else 1.0
        for _ in range(2):
            x_ref = _solved(s, rows, x_bound, x_ref, friction, False, slack, boundary_slack, kept, before)
            if x_ref.shape[0] == 0:
                return -1.0
    elif not _envelope(s, rows, x_bound, x_bound, False, False, slack, boundary_slack, kept, before)[4]:
        return -1.0  # without friction the interpolation pass's profile is not read: its checks only
    x = _solved(s, rows, x_bound, x_ref, friction, True, slack, boundary_slack, kept, before)
    if x.shape[0] == 0:
        return -1.0
    total = 0.0
    for i in range(s.shape[0] - 1):
        total += 2.0 * (s[i + 1] - s[i]) / max(np.sqrt(x[i]) + np.sqrt(x[i + 1]), 1e-300)
    return total


@njit(cache=True, nogil=True)
def _duration(q, dq, ddq, s, chain, limits, velocity_limited, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """The midpoint duration (s) on the grid s along the path of q, dq, ddq (N + 1, n_dof), -1
    where no timing follows it (``build_path_constraints`` then ``midpoint_duration``)."""
    parent, prismatic, axis, rotation, translation, coordinate, mass, lever, inertia, armature, gravity = chain
    coulomb, viscous, accelerated, acceleration, torqued, torque, velocity = limits
    n, dof = s.shape[0], q.shape[1]
    velocities = np.zeros((3, n, dof))
    accelerations = np.zeros((3, n, dof))
    velocities[2] = dq
    accelerations[1] = dq
    accelerations[2] = ddq
    m = accelerated.shape[0] + torqued.shape[0]
    a, b, c, d = np.empty((n, m)), np.empty((n, m)), np.empty((n, m)), np.empty((n, m))
    lower, upper = np.empty((n, m)), np.empty((n, m))
    tau = np.empty((3, n, dof))
    if torqued.shape[0]:
        rnea_sets(q, velocities, accelerations, parent, prismatic, axis, rotation, translation, coordinate, mass, lever, inertia, armature, gravity, tau)
    assemble_rows(dq, ddq, tau.reshape(3 * n, dof), coulomb, viscous, accelerated, acceleration, torqued, torque, a, b, c, d, lower, upper)
    x_bound = np.full(n, np.inf)
    if velocity_limited:
        binding = np.empty(n, dtype=np.int64)
        velocity_bound(dq, velocity, x_bound, binding)
        for i in range(n):
            x_bound[i] = x_bound[i] * x_bound[i]
    friction = False
    for i in range(n):
        for k in range(m):
            if d[i, k] != 0.0:
                friction = True
    return _midpoint_duration(s, (a, b, c, d, lower, upper), x_bound, friction, slack, boundary_slack, kept, before)


@njit(cache=True, nogil=True)
def _penalty(q, capsules, radius, kinds, rows, pairs, reach, ranges, clearance, settings):  # pragma: no cover - compiled
    """``local._Objective.penalty`` at the sample configurations q (S + 1, n_dof)."""
    first, second, pair_radius = pairs
    lower_limit, upper_limit, ranged = ranges
    margin, obstacle_weight, range_weight = settings
    count, dof = q.shape
    ends_a, ends_b = capsule_ends(q, *capsules)
    distance = np.full(count, np.inf)
    for o in range(kinds.shape[0]):
        lower_distances(ends_a, ends_b, radius, kinds[o], rows[o], clearance + 0.1, distance)
    if first.shape[0]:
        touching = np.empty(count)
        pair_minimum(ends_a, ends_b, first, second, pair_radius, touching)
        for i in range(count):
            distance[i] = min(distance[i], clearance + touching[i])
    total = 0.0
    if np.isfinite(distance).all():
        worst, summed = 0.0, 0.0
        for i in range(count - 1):
            motion = 0.0
            for j in range(dof):
                motion += abs(q[i + 1, j] - q[i, j]) * reach[j]
            inside = (distance[i] + distance[i + 1] - motion) / 2.0
            shortfall = max(clearance + margin - min(inside, distance[i]), 0.0)
            worst = max(worst, shortfall)
            summed += shortfall
        total += obstacle_weight * (worst + summed / (count - 1))
    if ranged.any():
        worst, summed = 0.0, 0.0
        for i in range(count):
            excursion = 0.0
            for j in range(dof):
                if ranged[j]:
                    excursion = max(excursion, max(lower_limit[j] - q[i, j], 0.0) + max(q[i, j] - upper_limit[j], 0.0))
            worst = max(worst, excursion)
            summed += excursion
        total += range_weight * (worst + summed / count)
    return total


@njit(cache=True, nogil=True)
def objective_value(inner, start, goal, spline, grid, samples, chain, limits, velocity_limited, distances, settings, infeasible, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """J(P) of ``local``'s module docstring for the interior control points ``inner``
    (flattened (k - 2) n_dof) between ``start`` and ``goal`` (n_dof,), on the knots of
    ``spline`` (knots and weights of ``basis_weights``): the midpoint duration on ``grid``
    (N + 1,; ``infeasible`` (s) where no timing follows the path) plus the penalties at
    ``samples`` (S + 1,), both in [0, 1].

    ``chain``: the arrays of ``toptraj.robots.chain.Chain``; ``limits``: (coulomb, viscous,
    acceleration joints, acceleration, torque joints, torque, velocity) as ``grid_rows`` and
    ``speed_bound`` read them; ``distances``: (capsule tables, capsule radii, obstacle kinds (O,),
    obstacle rows (O, 19), self-collision pairs (first, second, radius), joint reaches,
    (position lower, upper, ranged), clearance); ``settings``: (margin, obstacle weight, range
    weight); ``slack``, ``boundary_slack``, ``kept``, ``before``: as ``phase_plane.method``
    passes them to its sweeps."""
    dof = start.shape[0]
    count = inner.shape[0] // dof + 2
    control = np.empty((count, dof))
    control[0] = start
    control[count - 1] = goal
    for i in range(count - 2):
        for j in range(dof):
            control[i + 1, j] = inner[i * dof + j]
    knots, weights = spline
    coefficients = power_coefficients(control, weights)
    q, dq, ddq = cubic_pieces(knots, coefficients, grid)
    duration = _duration(q, dq, ddq, grid, chain, limits, velocity_limited, slack, boundary_slack, kept, before)
    if duration < 0.0:
        duration = infeasible
    capsules, radius, kinds, rows, pairs, reach, ranges, clearance = distances
    q = cubic_pieces(knots, coefficients, samples)[0]
    return duration + _penalty(q, capsules, radius, kinds, rows, pairs, reach, ranges, clearance, settings)
