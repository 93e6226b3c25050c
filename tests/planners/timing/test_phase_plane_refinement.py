"""The compiled phase-plane kernels against the numpy rows they replace, and the grid
refinement's error estimate against converged durations: from a coarse grid, the default
answer lands within its tolerance and holds the limits between its grid points."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.accuracy import KINDS, random_waypoints
from toptraj import robots
from toptraj.planners.checks.limit_check import check_limits
from toptraj.planners.constraints.admissible import acceleration_bounds, admissible_set
from toptraj.planners.constraints.admissible_kernels import NOTHING_BEFORE, NOTHING_KEPT, interval_bounds, zero_inertia_intervals
from toptraj.planners.constraints.path_constraints import PathConstraints, build_path_constraints
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.paths import SplinePath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing import PhasePlaneMethod
from toptraj.planners.timing.phase_plane.grid import interval_rows, kept_intervals, midpoint_stage_rows
from toptraj.planners.timing.phase_plane.method import midpoint_duration
from toptraj.planners.timing.phase_plane.refinement_kernels import row_excursions, switch_excess
from toptraj.planners.timing.phase_plane.split_kernels import _pieces

#: Largest |value| / limit on the dense check that the answer may reach: 0.3 % above the limit
#: (the service promises 0.5 % on any dense resampling, and a client's samples fall between
#: the check's states).
HELD = 1.003


def _random_constraints(rng, n_points: int, n_rows: int, friction: bool) -> PathConstraints:
    """Rows of random sign and size, some with a = 0 (zero inertia), a corner in the middle."""
    def rows():
        a = rng.normal(0, 1, (n_points, n_rows))
        a[::7, 1] = 0.0
        return a, rng.normal(0, 1, (n_points, n_rows)), rng.normal(0, 0.8, (n_points, n_rows))

    a, b, c = rows()
    a_left, b_left, c_left = a.copy(), b.copy(), c.copy()
    corner = n_points // 2
    a_left[corner], b_left[corner], c_left[corner] = (row[corner] for row in rows())
    d = rng.normal(0, 0.3, (n_points, n_rows)) * (rng.random((1, n_rows)) < 0.5) if friction else np.zeros((n_points, n_rows))
    d_left = d.copy()
    upper = np.full((n_points, n_rows), 1.0)
    upper[:, -1] = np.inf  # a row without limit
    sd_max = np.where(rng.random(n_points) < 0.4, rng.uniform(0.3, 2.0, n_points), np.inf)
    return PathConstraints(
        s=np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, n_points - 2)])),
        sd_max=sd_max, a=a, b=b, c=c, d=d, a_left=a_left, b_left=b_left, c_left=c_left, d_left=d_left,
        lower=-upper, upper=upper.copy(), rows=tuple(("torque", j) for j in range(n_rows)), joint_names=("j",) * n_rows,
    )  # fmt: skip


@pytest.mark.parametrize("friction", [False, True])
@pytest.mark.parametrize("midpoint", [False, True])
def test_interval_bounds_match_the_rows_they_stand_for(friction, midpoint):
    """The kernel builds each interval's bounds on u from the rows, linearizing friction
    itself; the same admissible x and the same tightest bounds on u at any x as the rows
    built in numpy (``PathConstraints.linearized``, ``interval_rows`` or
    ``midpoint_stage_rows``, then ``acceleration_bounds``)."""
    rng = np.random.default_rng(31)
    constraints = _random_constraints(rng, 120, 5, friction)
    x_ref = rng.uniform(0.1, 3.0, len(constraints.s))
    right, left = constraints.linearized(x_ref), constraints.linearized(x_ref, "left")
    stage = (midpoint_stage_rows if midpoint else interval_rows)(constraints.s, right, left)
    expected = admissible_set(stage, constraints.sd_max[:-1] ** 2)
    arrays = (constraints.a, constraints.b, constraints.c, constraints.d,
              constraints.a_left, constraints.b_left, constraints.c_left, constraints.d_left)  # fmt: skip
    p, q, r, x_low, x_high, _ = interval_bounds(
        constraints.s, *arrays, constraints.lower, constraints.upper, constraints.sd_max**2, x_ref, friction, midpoint,
        NOTHING_KEPT, NOTHING_BEFORE,
    )
    empty = expected.x_max < expected.x_min
    assert empty.sum() > 5 and (~empty).sum() > 5, empty.sum()  # both kinds of intervals are exercised
    assert np.array_equal(x_high < 0, empty)
    assert np.allclose(x_high[~empty], expected.x_max[~empty], rtol=1e-9, atol=1e-12)
    assert np.allclose(x_low[~empty], expected.x_min[~empty], rtol=1e-9, atol=1e-12)
    bounds = acceleration_bounds(stage)
    for x in (0.0, 0.5, 2.0):
        for kernel, numpy_ in ((p + q * x, bounds.p + bounds.q * x), (r + q * x, bounds.r + bounds.w * x)):
            largest = np.max(np.where(np.isfinite(kernel), kernel, -np.inf), axis=1)
            smallest = np.min(np.where(np.isfinite(kernel), kernel, np.inf), axis=1)
            theirs_largest = np.max(np.where(np.isfinite(numpy_), numpy_, -np.inf), axis=1)
            theirs_smallest = np.min(np.where(np.isfinite(numpy_), numpy_, np.inf), axis=1)
            assert np.allclose(largest, theirs_largest, rtol=1e-9) and np.allclose(smallest, theirs_smallest, rtol=1e-9)


@pytest.mark.parametrize("midpoint", [False, True])
def test_frictionless_interval_bounds_are_the_general_loop_without_friction(midpoint):
    """Without friction the kernel takes a loop of its own; with friction on and every viscous
    coefficient zero, the general loop splits each row into its half against the upper bound
    and its half against the lower bound, one bound on u each: together the same numbers, bit
    for bit."""
    rng = np.random.default_rng(7)
    constraints = _random_constraints(rng, 90, 4, friction=False)
    arrays = (constraints.a, constraints.b, constraints.c, constraints.d,
              constraints.a_left, constraints.b_left, constraints.c_left, constraints.d_left)  # fmt: skip
    x_ref = rng.uniform(0.1, 3.0, len(constraints.s))
    upper = rng.uniform(0.5, 2.0, constraints.upper.shape)
    upper[:, -1] = np.inf  # a row without limit
    common = (-rng.uniform(0.5, 2.0, upper.shape), upper, constraints.sd_max**2, x_ref)
    nothing = (NOTHING_KEPT, NOTHING_BEFORE)
    p, q, r, x_low, x_high, singular = interval_bounds(constraints.s, *arrays, *common, False, midpoint, *nothing)
    p2, q2, r2, x_low2, x_high2, singular2 = interval_bounds(constraints.s, *arrays, *common, True, midpoint, *nothing)
    width = p.shape[1]
    assert p2.shape[1] == 2 * width
    assert midpoint or singular.any()  # zero-inertia rows are exercised
    assert np.array_equal(singular, singular2)
    assert np.array_equal(x_low, x_low2) and np.array_equal(x_high, x_high2)
    assert np.array_equal(p, np.maximum(p2[:, :width], p2[:, width:]))
    assert np.array_equal(r, np.minimum(r2[:, :width], r2[:, width:]))
    assert np.array_equal(q, q2[:, :width]) and np.array_equal(q, q2[:, width:])


@pytest.mark.parametrize("midpoint", [False, True])
def test_interval_bounds_kept_from_a_coarser_grid_are_the_bounds_computed_afresh(midpoint):
    """The bounds of the intervals a refined grid keeps whole, copied from the coarser grid's
    (``kept``, ``before``), and those computed for the new ones are the bounds computed afresh on
    the refined grid, bit for bit (zero-inertia rows, a corner and empty intervals among them);
    with friction nothing is copied, since the rows' linearization may have moved."""
    rng = np.random.default_rng(12)
    fine = _random_constraints(rng, 150, 4, friction=False)
    coarse_points = np.flatnonzero((np.arange(150) % 3 != 1) | (np.arange(150) < 60))
    arrays = (fine.a, fine.b, fine.c, fine.d, fine.a_left, fine.b_left, fine.c_left, fine.d_left, fine.lower, fine.upper)
    x_bound = fine.sd_max**2

    def bounds(points, kept, before, friction=False):
        rows = (np.ascontiguousarray(array[points]) for array in arrays)
        return interval_bounds(fine.s[points], *rows, x_bound[points], x_bound[points], friction, midpoint, kept, before)[:5]

    everything = np.arange(150)
    before = bounds(coarse_points, NOTHING_KEPT, NOTHING_BEFORE)
    kept = kept_intervals(fine.s, fine.s[coarse_points])
    assert 50 < (kept >= 0).sum() < 140  # some intervals kept, some new
    afresh = bounds(everything, NOTHING_KEPT, NOTHING_BEFORE)
    for copied, computed in zip(bounds(everything, kept, before), afresh):
        np.testing.assert_array_equal(copied, computed)
    assert (afresh[4] < 0).any() and (afresh[4] >= 0).any()  # empty and admissible intervals
    wrong = tuple(array + 1.0 for array in before)
    copied_x_low = bounds(everything, kept, wrong)[3]
    np.testing.assert_array_equal(copied_x_low[kept >= 0], afresh[3][kept >= 0] + 1.0)  # read, not recomputed
    np.testing.assert_array_equal(copied_x_low[kept < 0], afresh[3][kept < 0])
    # With friction the kept bounds are not read.
    for friction_bounds, computed in zip(bounds(everything, kept, wrong, True), bounds(everything, NOTHING_KEPT, NOTHING_BEFORE, True)):
        np.testing.assert_array_equal(friction_bounds, computed)


def test_switch_excess_of_a_start_from_rest_is_the_closed_form():
    """One interval of length L from rest to x1 = sd_1^2 under u <= beta and x <= x1: the
    constant-u interval takes 2 L / sd_1; at the bounds, accelerating to x1 in x1 / (2 beta)
    and then cruising takes sd_1 / beta + (L - x1 / (2 beta)) / sd_1."""
    length, beta, x1 = 0.1, 3.0, 0.25
    r = np.array([[beta]])
    q = np.zeros((1, 1))
    p = np.array([[-10.0]])
    excess = switch_excess(np.array([length]), p, q, r, np.array([0.0, x1]), np.array([x1, x1]))
    sd_1 = np.sqrt(x1)
    exact = 2 * length / sd_1 - (sd_1 / beta + (length - x1 / (2 * beta)) / sd_1)
    assert excess[0] == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_refinement_splits_into_the_fewest_whole_pieces(seed):
    """The pieces per interval are whole numbers: the fewest in all that bring the summed error
    ``first / k + second / k^2`` to ``shrink`` times its value, against every allocation of up
    to 6 pieces to each of 5 intervals (6^5 of them)."""
    rng = np.random.default_rng(seed)
    first = rng.exponential(1.0, 5) * (rng.random(5) < 0.8)
    second = rng.exponential(1.0, 5) * (rng.random(5) < 0.6)
    shrink = rng.uniform(0.3, 0.9)
    pieces = np.ones(5)
    _pieces(first, second, shrink, 6, 10**9, pieces)
    grids = np.stack(np.meshgrid(*([np.arange(1.0, 7.0)] * 5), indexing="ij"), axis=-1).reshape(-1, 5)
    errors = (first / grids + second / grids**2).sum(axis=1)
    target = shrink * (first + second).sum()
    fewest = grids[errors <= target * (1 + 1e-12)].sum(axis=1).min()
    assert np.all(pieces == np.round(pieces)) and pieces.max() <= 6
    assert (first / pieces + second / pieces**2).sum() <= target * (1 + 1e-12)
    assert pieces.sum() == fewest


def test_refinement_beyond_one_round_splits_as_the_real_allocation():
    """Where ``max_pieces`` keeps one round from reaching the target, every interval takes the
    real allocation of each error part on its own (k_i proportional to e_i^(1 / (order + 1)),
    scaled to bring the part to ``shrink`` times itself) rounded up, at most ``max_pieces``:
    the grid's shares for the next round, not every interval at the cap."""
    rng = np.random.default_rng(3)
    first, second = rng.exponential(1.0, 40), rng.exponential(1.0, 40) * (rng.random(40) < 0.5)
    shrink, max_pieces = 0.01, 8
    real = np.ones(40)
    for error, order in ((first, 1.0), (second, 2.0)):
        roots = error ** (1 / (order + 1))
        real = np.maximum(real, roots * (roots.sum() / (shrink * error.sum())) ** (1 / order))
    pieces = np.ones(40)
    _pieces(first, second, shrink, max_pieces, 10**9, pieces)
    assert (first / pieces + second / pieces**2).sum() > shrink * (first + second).sum()  # out of reach
    np.testing.assert_array_equal(pieces, np.minimum(np.ceil(real), max_pieces))
    assert 1 < pieces.min() and pieces.min() < max_pieces  # the shares differ


@pytest.mark.parametrize("seed", range(4))
def test_refinement_with_little_room_left_takes_the_pieces_that_remove_the_most_error(seed):
    """Where the grid's cap leaves room for fewer new points than the target asks, the pieces
    are the ``room`` that leave the least summed error, against every allocation of up to 6
    pieces to each of 5 intervals with at most ``room`` new ones."""
    rng = np.random.default_rng(seed)
    first, second = rng.exponential(1.0, 5), rng.exponential(1.0, 5) * (rng.random(5) < 0.6)
    shrink, room = 0.2, 4
    pieces = np.ones(5)
    _pieces(first, second, shrink, 6, room, pieces)
    grids = np.stack(np.meshgrid(*([np.arange(1.0, 7.0)] * 5), indexing="ij"), axis=-1).reshape(-1, 5)
    errors = (first / grids + second / grids**2).sum(axis=1)
    fitting = (grids - 1).sum(axis=1) <= room
    assert errors[fitting].min() > shrink * (first + second).sum() and (pieces - 1).sum() == room  # room used up
    assert (first / pieces + second / pieces**2).sum() == pytest.approx(errors[fitting].min(), rel=1e-12)


def _converged(path, robot) -> float:
    """Richardson extrapolation of the conservative discretization on 4,000 and 8,000
    intervals, checked against the midpoint discretization on 8,000."""
    unrefined = PhasePlaneMethod(max_refinements=0)
    coarse = path_grid(path, 4000)
    fine = np.sort(np.concatenate([coarse, 0.5 * (coarse[:-1] + coarse[1:])]))
    durations = [unrefined.solve(build_path_constraints(path, robot, robot.limits, KINDS, grid)).duration for grid in (coarse, fine)]
    converged = 2 * durations[1] - durations[0]
    check = midpoint_duration(build_path_constraints(path, robot, robot.limits, KINDS, fine))
    assert check == pytest.approx(converged, rel=3e-5)
    return converged


@pytest.mark.parametrize("name", ["ur5", "panda", "geering_2r", "yamamoto_2r"])
def test_a_coarse_grid_is_refined_to_the_tolerance(name):
    """From 25 intervals, where a start from rest, a switch onto the maximum velocity curve or
    a stretch along its curved part lies inside one interval, the estimate sees the error and
    the default answer ends within 0.1 % of the converged duration (estimated within its
    tolerance of 0.06 %)."""
    robot = robots.load(name)
    rng = np.random.default_rng(5)
    compared = 0
    while compared < 3:
        path = SplinePath(random_waypoints(robot, rng))
        try:
            converged = _converged(path, robot)
        except InfeasiblePath:
            continue
        result = PhasePlaneMethod().solve(build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, 25)))
        assert abs(result.duration / converged - 1) <= 1e-3, (name, compared, result.duration, converged, len(result.s))
        compared += 1


def _excursions(c, x_bound, target):
    """``row_excursions`` of one row ``u + c(s)`` in [-1, 1] (a = 1, b = d = 0) and the speed
    bound x <= x_bound (joint 0 binding throughout) on the grid s = 0, 0.1, ..., 1, with x = 1
    throughout (u = 0)."""
    n = len(c)
    ones, zeros = np.ones((n, 1)), np.zeros((n, 1))
    rows = (ones, zeros, c[:, None], zeros)
    s, binding, smooth = np.linspace(0.0, 1.0, n), np.zeros(n, dtype=np.int64), np.ones(n, dtype=bool)
    return row_excursions(s, *rows, *rows, -ones, ones.copy(), x_bound, binding, smooth, np.ones(n), target, 8)


def test_row_excursions_split_as_the_closed_form_asks():
    """A row and a speed bound that hold at both ends of the interval [0.5, 0.6] and bulge
    between them by a parabola: c(s) = 1 + K ((h/2)^2 - (s - 0.55)^2) peaks at 1 + K h^2 / 4
    midway (the cubic through four grid points is exact for it), so the interval is split into
    ceil(sqrt(K h^2 / 4 / target)) pieces and no other; likewise 1 / x_bound with x = 1, where
    the velocity peaks at sqrt(1 + K h^2 / 4) of its limit."""
    s = np.linspace(0.0, 1.0, 11)
    bulge = 0.0025 - (s - 0.55) ** 2  # (h/2)^2 - (s - s_m)^2: zero at 0.5 and 0.6
    target = 3e-4
    least = _excursions(1.0 + 1.0 * bulge, np.full(11, np.inf), target)
    expected = np.ones(10, dtype=int)
    expected[5] = np.ceil(np.sqrt(1.0 * 0.0025 / target))  # 3
    np.testing.assert_array_equal(least, expected)

    speed = 1.0 / (1.0 + 4.0 * bulge)  # x_bound: x = 1 touches it at 0.5 and 0.6
    least = _excursions(np.zeros(11), speed, target)
    expected[5] = np.ceil(np.sqrt((np.sqrt(1.0 + 4.0 * 0.0025) - 1.0) / target))  # 5
    np.testing.assert_array_equal(least, expected)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_a_coarse_grid_holds_the_limits_between_its_points(name):
    """On 30 intervals (a few per spline segment) the rows hold at the grid points only; the
    refinement of their excursions keeps every limit within the gate's tolerance on the dense
    check without the gate's help, where refining for the duration alone exceeds it."""
    robot = robots.load(name)
    rng = np.random.default_rng(11)
    worst = {"default": 1.0, "duration only": 1.0}
    for _ in range(8):
        path = SplinePath(random_waypoints(robot, rng))
        constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path, 30))
        for label, method in (("default", PhasePlaneMethod()), ("duration only", PhasePlaneMethod(excursion=None))):
            try:
                timing = method.solve(constraints)
            except InfeasiblePath:
                continue
            utilization = check_limits(path, timing, robot, robot.limits).utilization
            worst[label] = max(worst[label], max(value.max() for value in utilization.values()))
    assert worst["default"] <= HELD
    assert worst["duration only"] > HELD


@pytest.mark.parametrize("name", ["ur5", "yamamoto_2r"])
def test_a_refined_answer_is_the_answer_on_its_own_grid_built_afresh(name):
    """The rows at the points refinement adds are the build's own (the RNEA there, not an
    estimate): the refined speed equals, bit for bit, the unrefined method's on the final grid
    built afresh."""
    robot = robots.load(name)
    if name == "ur5":  # the README's typical request: 301 grid points refined to 542
        waypoints = np.array([[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]])
    else:
        waypoints = random_waypoints(robot, np.random.default_rng(11))
    path = SplinePath(waypoints)
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path))
    refined = PhasePlaneMethod().solve(constraints)
    assert len(refined.s) > len(constraints.s)  # refinement added points
    fresh = build_path_constraints(path, robot, robot.limits, KINDS, refined.s)
    np.testing.assert_array_equal(PhasePlaneMethod(max_refinements=0).solve(fresh).sd, refined.sd)


def test_zero_inertia_intervals_are_the_interval_rows_with_a_vanishing_u_coefficient():
    """``zero_inertia_intervals`` marks the intervals whose rows in the interpolation
    discretization (``interval_rows``, built in numpy) have a u-coefficient within the threshold
    of their scale |a| + |b|: rows with a = 0 at grid points, and rows whose coefficient the
    interval's far end cancels (a_left + 2 ds b_left = 0)."""
    rng = np.random.default_rng(8)
    constraints = _random_constraints(rng, 200, 5, False)
    s = constraints.s
    far = 40  # a row that vanishes only as interval 40 sees its far end
    constraints.a_left[far + 1, 3] = -2.0 * (s[far + 1] - s[far]) * constraints.b_left[far + 1, 3]
    right = constraints.linearized(np.ones(len(s)))
    left = constraints.linearized(np.ones(len(s)), "left")
    stage = interval_rows(s, right, left)
    size = np.abs(stage.a)
    expected = (size <= 1e-6 * np.maximum(size + np.abs(stage.b), 1e-300)).any(axis=1)
    intervals = np.arange(len(s) - 1, dtype=np.int64)
    found = zero_inertia_intervals(s, constraints.a, constraints.b, constraints.a_left, constraints.b_left, intervals, 1e-6)
    np.testing.assert_array_equal(found, expected)
    assert expected[far] and 20 < expected.sum() < len(intervals)
