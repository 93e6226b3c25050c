"""Joint torques between the grid points of a path's constraints, from the rows the build
computed there with the RNEA (numba, ``nogil``, cached): the dense limit check's torques
(``toptraj.planners.checks.limit_check``) without a dynamics evaluation per state where the interpolation is
accurate, and with one where it is not. (The rows a refining method adds at new grid points
take the RNEA itself, ``PathConstraints.with_points``: with the compiled pass of
``toptraj.robots.chain_dynamics`` that is as fast as interpolating them, and exact.)

Along q(s) the torque of joint j at a state (s, sd, sdd) is (Jeong & Lee eq. (3.4b) with
x = sd^2, u = sdd, and the URDF's joint friction)

    tau_j = a_j(s) u + b_j(s) x + g_j(s) + d_j(s) sd + F_j sign(q'_j(s) sd),

with a = M q', b = M q'' + C(q, q') q', g the gravity torque and d = D q' (N m s^2, N m s^2,
N m and N m s), each smooth in s between the path's knots (q(s) is a polynomial there, and the
dynamics trigonometric in q). The rows ``a u + b x + c + d sd`` hold a, b, d and
c = g + F sign(q') at the grid points, the Coulomb term with the grid point's sign: with
Coulomb friction, the points between grid points take RNEA. At a point between grid points,
each of a, b, c and d is read from the quartic (Newton's divided differences, on the
non-uniform grid) through five consecutive grid points that no knot, corner or break of the
path separates, the interval holding the point among the middle ones where the run of smooth
points allows. Its error is estimated by the larger difference from the cubics through the
first and the last four of those points (their error is one order lower; each equals the
quartic's top coefficient times a product of node distances; each row apart, weighted by |u|,
x, 1 and sd, since the rows' errors may cancel at one point and add up at the next). A point is
left to RNEA where that estimate exceeds ``tolerance`` of its scale, where fewer than five
smooth grid points surround it, or where an interval among them moves the joints by more than
``MAX_TRAVEL``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj.compiled import njit

if TYPE_CHECKING:
    from toptraj.planners.constraints.path_constraints import PathConstraints

#: Largest joint travel (rad, summed over the joints) of a grid interval whose rows are
#: interpolated: the rows are trigonometric in q, and a grid coarser than this does not resolve
#: them well enough for the interpolation's error estimate to be trusted (on ur5 with 60
#: intervals over moves of several rad, a cubic and a quartic agree and both miss by 3.6e-5
#: of the limit).
MAX_TRAVEL = 0.1


def smooth_points(constraints: PathConstraints) -> np.ndarray:
    """(N + 1,): the grid points of ``constraints`` (a ``PathConstraints``) through which the
    rows are smooth, so that a polynomial through them interpolates the rows: interior, no knot
    of the path, the same rows from both sides (also where ``phase_plane``'s excursion estimate,
    ``toptraj.planners.timing.phase_plane.refinement_kernels.row_excursions``, may reach across a grid point)."""
    grid = constraints.s
    smooth = np.ones(len(grid), dtype=bool)
    smooth[[0, -1]] = False
    if constraints.knots is not None and len(constraints.knots):
        at = np.minimum(np.searchsorted(grid, constraints.knots), len(grid) - 1)
        smooth[at[grid[at] == constraints.knots]] = False
    sides = ((constraints.a, constraints.a_left), (constraints.b, constraints.b_left),
             (constraints.c, constraints.c_left), (constraints.d, constraints.d_left))
    for right, left in sides:
        if right is not left:
            smooth &= np.all(right == left, axis=1)
    return smooth


def grid_travel(constraints: PathConstraints) -> np.ndarray | None:
    """(N,): the joints' travel over each grid interval of ``constraints``, the sum over the
    joints of |q(s_i+1) - q(s_i)| (rad); ``None`` when its grid's points are unknown."""
    return None if constraints.q is None else np.abs(np.diff(constraints.q, axis=0)).sum(axis=1)


@njit(cache=True, nogil=True)
def _stencil(smooth, travel, max_travel, i):  # pragma: no cover - compiled
    """The first of five consecutive grid points around interval i through which the rows are
    smooth and which the grid resolves (each interval among them moving the joints by at most
    ``max_travel``), the interval among the middle ones where the run of smooth points allows;
    -1 where there are none."""
    n_grid = smooth.shape[0]
    lo = i
    while lo > i - 2 and lo > 0 and smooth[lo]:
        lo -= 1
    hi = i + 1
    while hi < i + 3 and hi < n_grid - 1 and smooth[hi]:
        hi += 1
    if hi - lo + 1 < 5:
        return -1
    start = min(max(i - 2, lo), hi - 4)
    for node in range(start, start + 4):
        if not travel[node] <= max_travel:
            return -1
    return start


@njit(cache=True, nogil=True)
def _divided_differences(grid, right, left, columns, i, start, coefficients, spans):  # pragma: no cover - compiled
    """Newton coefficients f[x0], f[x0, x1], ..., f[x0, ..., x4] of the quartic through the five
    grid points from ``start`` of each row of ``right`` and ``left`` (tuples of (N + 1, m)
    arrays, seen from the right and from the left of each point), columns ``columns`` (k,), into
    ``coefficients`` (rows, k, 5); ``spans`` (5, 5) is scratch for 1 / (x_k - x_k-order). A node
    beyond interval i's far end is seen from the left, as the interval sees it."""
    for order in range(1, 5):
        for k in range(order, 5):
            spans[order, k] = 1.0 / (grid[start + k] - grid[start + k - order])
    for row in range(len(right)):
        for j in range(columns.shape[0]):
            column = columns[j]
            for k in range(5):
                node = start + k
                coefficients[row, j, k] = left[row][node, column] if node > i else right[row][node, column]
            for order in range(1, 5):
                for k in range(4, order - 1, -1):
                    coefficients[row, j, k] = (coefficients[row, j, k] - coefficients[row, j, k - 1]) * spans[order, k]


@njit(cache=True, nogil=True)
def _node_products(grid, start, at, products):  # pragma: no cover - compiled
    """(x - x0), (x - x0)(x - x1), ..., (x - x0)...(x - x3) at x = ``at`` for the five nodes from
    ``start``, into ``products[1:5]`` (``products[0]`` = 1), and (x - x1)...(x - x4) into
    ``products[5]``. The quartic minus the cubic through its first four nodes is
    f[x0..x4] products[4], minus the cubic through its last four f[x0..x4] products[5]."""
    products[0] = 1.0
    for k in range(1, 5):
        products[k] = products[k - 1] * (at - grid[start + k - 1])
    shifted = 1.0
    for k in range(1, 5):
        shifted *= at - grid[start + k]
    products[5] = shifted


@njit(cache=True, nogil=True)
def _row_at(coefficients, row, j, products):  # pragma: no cover - compiled
    """(value, estimated error) of row ``row`` of joint j: the quartic's value (Newton form) and
    its larger difference from the two cubics through four of its nodes."""
    value = 0.0
    for k in range(4, -1, -1):
        value += coefficients[row, j, k] * products[k]
    top = abs(coefficients[row, j, 4])
    return value, top * max(abs(products[4]), abs(products[5]))


@njit(cache=True, nogil=True, error_model="numpy")
def dense_torques(grid, smooth, right, left, columns, travel, max_travel, limit, s, sd, sdd, from_left, interpolate, tolerance, tau, exact) -> None:  # pragma: no cover - compiled
    """Write a u + b x + c + d sd, the torques of n states (s, sd, u = sdd, x = sd^2), into
    ``tau`` (n, n_dof), and mark in ``exact`` (n,) the states left to RNEA (their rows of
    ``tau`` unset). A moving state on a grid point reads the rows there, on its side; a state
    between grid points reads them from the quartic through the five grid points around it
    (``_stencil``) where ``interpolate`` and the estimated error of every joint's torque is
    within ``tolerance`` of its limit.

    Args:
        grid: Grid of s the rows were built on, (N + 1,).
        smooth: (N + 1,): the rows are smooth through the grid point (an interior point that is
            no knot of the path and where the rows from both sides agree).
        right, left: The rows a, b, c and d at each grid point, a tuple of four (N + 1, m),
            from the right and from the left of the point (they differ at corners and breaks).
        columns: The torque row of each joint, (n_dof,).
        travel: Sum over the joints of |q(s_i+1) - q(s_i)| of each grid interval, (N,), rad.
        max_travel: Largest ``travel`` of an interval whose rows are interpolated: a coarser
            grid does not resolve rows trigonometric in q well enough for the estimate.
        limit: Torque limit per joint, (n_dof,), N m (finite): the scale of ``tolerance``.
        s, sd, sdd: The states, (n,) each, s within [grid[0], grid[-1]].
        from_left: (n,): the state ends the interval before its grid point (else it starts the
            one after, or lies inside one).
        interpolate: Whether states between grid points may be interpolated at all (c holds
            no Coulomb friction, whose sign differs between the grid points and the states).
        tolerance: Largest estimated interpolation error trusted, a fraction of the limit.
    """
    n_grid = grid.shape[0]
    n_dof = columns.shape[0]
    coefficients = np.empty((4, n_dof, 5))
    spans = np.empty((5, 5))
    products = np.empty(6)
    factors = np.empty(4)
    held = (-1, -1)  # the interval and stencil whose coefficients are held
    rows = 4  # the rows with a nonzero coefficient in the held stencil (d, the viscous row, last)
    k = 0
    stencil_of, start = -1, -1  # the interval whose stencil ``start`` is
    for state in range(s.shape[0]):
        at = s[state]
        speed = sd[state]
        factors[0], factors[1], factors[2], factors[3] = sdd[state], speed * speed, 1.0, speed
        # The states come in order of s (mostly): step the search on from the last one.
        if k > 0 and grid[k - 1] >= at:
            k = np.searchsorted(grid, at)
        while k < n_grid and grid[k] < at:
            k += 1
        on_grid = k < n_grid and grid[k] == at
        if on_grid and speed > 0.0:
            a, b, c, d = left if from_left[state] else right
            for j in range(n_dof):
                column = columns[j]
                tau[state, j] = a[k, column] * factors[0] + b[k, column] * factors[1] + c[k, column] + d[k, column] * speed
            continue
        if not interpolate:
            exact[state] = True
            continue
        # The interval the state belongs to: the one ending at its grid point from the left.
        i = k - 1 if (from_left[state] or not on_grid) else k
        i = min(max(i, 0), n_grid - 2)
        if i != stencil_of:
            start = _stencil(smooth, travel, max_travel, i)
            stencil_of = i
        if start < 0:
            exact[state] = True
            continue
        if held != (i, start):
            _divided_differences(grid, right, left, columns, i, start, coefficients, spans)
            held = (i, start)
            # Without viscous friction the d row is zero throughout, and so are its value and
            # its error: three rows give the same sums.
            rows = 3
            for j in range(n_dof):
                for node in range(5):
                    if coefficients[3, j, node] != 0.0:
                        rows = 4
        _node_products(grid, start, at, products)
        for j in range(n_dof):
            # Each row's error apart: the rows' errors may cancel in one state's torque and
            # add up in the next one's.
            value = 0.0
            error = 0.0
            for row in range(rows):
                factor = factors[row]
                if factor != 0.0:
                    row_value, row_error = _row_at(coefficients, row, j, products)
                    value += factor * row_value
                    error += abs(factor) * row_error
            if not error <= tolerance * limit[j]:
                exact[state] = True
                break
            tau[state, j] = value
