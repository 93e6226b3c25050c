"""The local optimization's objective J(P) (``toptraj.planners.generators.search.local``) in one
compiled call: from the interior control points to the midpoint duration plus the penalties,
the same computation as the reference path (``BSplinePath``, ``build_path_constraints``,
``midpoint_duration``, ``free_distances``) without building any of its objects.

The spline is evaluated from precomputed basis weights: at each grid point only four B-spline
basis functions are nonzero (de Boor, *A Practical Guide to Splines*, 2001, ch. IX), so
q^(nu)(s_i) = sum_{r<4} W_nu[i, r] P[first_i + r], with W_nu the nu-th derivatives of those four
functions at s_i (``basis_weights``). The rows are then written by the same kernels as
``build_path_constraints`` (``robots.chain_dynamics.rnea_sets``, ``assembly_kernels``), swept by
the phase-plane kernels as ``midpoint_duration`` sweeps them (the interpolation pass, twice with
viscous friction, then the midpoint pass), and the distance lower bound of the penalty comes
from ``distance_kernels`` as in ``free_space.point_distances``. The answers equal the reference
path's to rounding (tests/planners/generators/test_search_objective.py).

Shapes: control points (k, n_dof); grid N + 1 points; obstacle samples S + 1 points; m rows.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from toptraj.planners.constraints.admissible_kernels import point_bounds
from toptraj.planners.constraints.assembly_kernels import assemble_rows, velocity_bound
from toptraj.planners.generators.search.distance_kernels import capsule_ends, lower_distances, pair_minimum
from toptraj.planners.timing.phase_plane.sweep_kernels import sweeps
from toptraj.robots.chain_dynamics import rnea_sets


def basis_weights(knots: np.ndarray, s: np.ndarray, degree: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The index of the first nonzero basis function at each s (len(s),) and the values and
    first two derivatives of the ``degree + 1`` nonzero ones, (3, len(s), degree + 1), of the
    clamped spline on the full knot vector ``knots``: the weights of ``objective_value``."""
    from scipy.interpolate import BSpline  # here: the searches' paths only

    count = len(knots) - degree - 1
    basis = BSpline(knots, np.eye(count), degree)
    span = np.clip(np.searchsorted(knots, s, side="right") - 1, degree, count - 1)
    first = (span - degree).astype(np.int64)
    columns = first[:, None] + np.arange(degree + 1)[None, :]
    weights = np.stack([np.take_along_axis(basis(s, nu), columns, axis=1) for nu in range(3)])
    return first, np.ascontiguousarray(weights)


@njit(cache=True, nogil=True)
def _spline(control, first, weights, nu, out):  # pragma: no cover - compiled
    """out (len(first), n_dof) = the nu-th derivative of the spline at the points of ``first``."""
    for i in range(first.shape[0]):
        for j in range(control.shape[1]):
            total = 0.0
            for r in range(weights.shape[2]):
                total += weights[nu, i, r] * control[first[i] + r, j]
            out[i, j] = total


@njit(cache=True, nogil=True)
def _solved(s, rows, x_bound, x_ref, friction, midpoint, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """``phase_plane.method._integrate`` at rest at both ends: x (N + 1,), or an empty array
    where it raises (the path cannot be timed)."""
    a, b, c, d, lower, upper = rows
    x_start, x_end = 0.0, 0.0
    if x_end > x_bound[-1] * (1 + slack) + slack:
        return np.empty(0)
    x, _, envelope, floor, failed, _, _, _ = sweeps(
        s, a, b, c, d, a, b, c, d, lower, upper, x_bound, x_ref, friction, x_start, x_end, midpoint, slack, kept, before
    )
    if failed >= 0 or x_start < floor[0] * (1 - 1e-7) - 1e-12 or x_start > envelope[0] * (1 + boundary_slack) + 1e-12:
        return np.empty(0)
    x[0], x[-1] = x_start, x_end
    for i in range(x.shape[0]):
        if x[i] < 0.0:
            x[i] = 0.0
    return x


@njit(cache=True, nogil=True)
def _midpoint_duration(s, rows, x_bound, friction, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """``phase_plane.method.midpoint_duration`` at rest (s), or -1 where no timing follows."""
    a, b, c, _, lower, upper = rows
    passes = 1
    x_ref = x_bound
    if friction:
        passes = 2
        x_max = point_bounds(a, b, c, lower, upper, x_bound)[4]
        x_ref = np.empty(x_max.shape[0])
        for i in range(x_max.shape[0]):
            x_ref[i] = x_max[i] if np.isfinite(x_max[i]) and x_max[i] > 0 else 1.0
    for _ in range(passes):
        x_ref = _solved(s, rows, x_bound, x_ref, friction, False, slack, boundary_slack, kept, before)
        if x_ref.shape[0] == 0:
            return -1.0
    x = _solved(s, rows, x_bound, x_ref, friction, True, slack, boundary_slack, kept, before)
    if x.shape[0] == 0:
        return -1.0
    total = 0.0
    for i in range(s.shape[0] - 1):
        total += 2.0 * (s[i + 1] - s[i]) / max(np.sqrt(x[i]) + np.sqrt(x[i + 1]), 1e-300)
    return total


@njit(cache=True, nogil=True)
def _duration(control, s, first, weights, chain, limits, velocity_limited, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """The midpoint duration (s) along the spline of ``control`` on the grid s, -1 where no
    timing follows it (``build_path_constraints`` then ``midpoint_duration``)."""
    parent, prismatic, axis, rotation, translation, coordinate, mass, lever, inertia, armature, gravity = chain
    coulomb, viscous, accelerated, acceleration, torqued, torque, velocity = limits
    n, dof = s.shape[0], control.shape[1]
    velocities = np.zeros((3, n, dof))
    accelerations = np.zeros((3, n, dof))
    q = np.empty((n, dof))
    _spline(control, first, weights, 0, q)
    _spline(control, first, weights, 1, velocities[2])
    _spline(control, first, weights, 1, accelerations[1])
    _spline(control, first, weights, 2, accelerations[2])
    dq, ddq = velocities[2], accelerations[2]
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
def objective_value(inner, start, goal, grid, samples, chain, limits, velocity_limited, distances, settings, infeasible, slack, boundary_slack, kept, before):  # pragma: no cover - compiled
    """J(P) of ``local``'s module docstring for the interior control points ``inner``
    (flattened (k - 2) n_dof) between ``start`` and ``goal`` (n_dof,): the midpoint duration
    on ``grid`` (s, first, weights of ``basis_weights``; ``infeasible`` (s) where no timing
    follows the path) plus the penalties at ``samples`` (first, weights).

    ``chain``: the arrays of ``toptraj.robots.chain.Chain``; ``limits``: (coulomb, viscous,
    acceleration joints, acceleration, torque joints, torque, velocity) as ``grid_rows`` and
    ``speed_bound`` read them; ``distances``: (capsule tables, capsule radii, obstacle kinds (O,),
    obstacle rows (O, 19), self-collision pairs (first, second, radius), joint reaches,
    (position lower, upper, ranged), clearance); ``settings``: (margin, obstacle weight, range
    weight); ``slack``, ``boundary_slack``, ``kept``, ``before``: as ``phase_plane.method``
    passes them to ``sweeps``."""
    dof = start.shape[0]
    count = inner.shape[0] // dof + 2
    control = np.empty((count, dof))
    control[0] = start
    control[count - 1] = goal
    for i in range(count - 2):
        for j in range(dof):
            control[i + 1, j] = inner[i * dof + j]
    s, first, weights = grid
    duration = _duration(control, s, first, weights, chain, limits, velocity_limited, slack, boundary_slack, kept, before)
    if duration < 0.0:
        duration = infeasible
    capsules, radius, kinds, rows, pairs, reach, ranges, clearance = distances
    q = np.empty((samples[0].shape[0], dof))
    _spline(control, samples[0], samples[1], 0, q)
    return duration + _penalty(q, capsules, radius, kinds, rows, pairs, reach, ranges, clearance, settings)
