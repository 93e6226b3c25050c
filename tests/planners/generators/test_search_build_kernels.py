"""The search build's compiled shortcuts against the computations they replace, on random
inputs: the box and self-collision distances computed only where a bound says they may lower
the least (``distance_kernels.lower_distances``, ``pair_minimum``) against every distance
computed (the same least to the bit, and the numpy distances of
``toptraj.planners.collision.distance`` to rounding); the samples along the spans
(``span_kernels.span_points``) against ``curve.span_values``; the pieces' samples held once
per piece; and the pieces' bounds, their rows computed once per sample
(``bounds.piece_bounds``), against the rows computed at both ends of every interval as
before."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners.collision import BoxObstacle
from toptraj.planners.collision.distance import capsule_distance, segment_distance
from toptraj.planners.collision.self_collision import self_pairs
from toptraj.planners.constraints.admissible_kernels import NOTHING_BEFORE, NOTHING_KEPT, interval_bounds, point_bounds
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.generators.search import bounds
from toptraj.planners.generators.search.curve import BASIS, span_values
from toptraj.planners.generators.search.distance_kernels import (
    _capsules_apart,
    _in_box_frame,
    _point_segment,
    box_bound,
    capsule_ends,
    lower_distances,
    obstacle_row,
    pair_minimum,
    segment_box,
)
from toptraj.planners.generators.search.free_space import chain_tables
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.pieces import INTERVALS
from toptraj.planners.generators.search.problem import build_problem
from toptraj.planners.generators.search.span_kernels import span_points

BOXES = (
    BoxObstacle(np.array([0.45, 0.1, 0.35]), np.array([0.15, 0.15, 0.15])),
    BoxObstacle(np.array([0.3, -0.2, 0.4]), np.array([0.2, 0.1, 0.3]), np.array([0.1, 0.2, 0.3, 0.927]) / np.linalg.norm([0.1, 0.2, 0.3, 0.927])),
)
UR5 = (np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0]))
PANDA = (np.array([-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]), np.array([0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]))


def _ends(arm: str, count: int, seed: int):
    """Capsule ends (count, C, 3) at random configurations of ``arm`` and the capsules' radii."""
    robot = robots.load(arm)
    q = np.random.default_rng(seed).uniform(-2.5, 2.5, (count, robot.dof))
    tables = chain_tables(robot)
    a, b = capsule_ends(q, *tables[0])
    return robot, a, b, tables[1]


def _every_box_distance(a, b, radius, row, exact_below):
    """The least over the capsules of the exact box distance (``segment_box``) where the ball
    bound is below the threshold, the ball bound elsewhere: every distance computed."""
    center = row[0:3]
    to_center = np.array([[_point_segment(center, a[i, c], b[i, c]) - radius[c] for c in range(a.shape[1])] for i in range(len(a))])
    threshold = max(exact_below, to_center.min())
    out = np.full(len(a), np.inf)
    local = np.empty(6)
    for i in range(len(a)):
        for c in range(a.shape[1]):
            lower = to_center[i, c] - row[6]
            if lower < threshold:
                _in_box_frame(a, b, i, c, row, local)
                lower = segment_box(local, row) - radius[c]
            out[i] = min(out[i], lower)
    return out


@pytest.mark.parametrize("arm", ["ur5", "panda"])
@pytest.mark.parametrize("box", BOXES)
@pytest.mark.parametrize("exact_below", [np.inf, 0.04, 0.12])
def test_box_distances_equal_every_exact_distance(arm, box, exact_below):
    _, a, b, radius = _ends(arm, 400, 5)
    kind, row = obstacle_row(box)
    ours = np.full(len(a), np.inf)
    lower_distances(a, b, radius, kind, row, exact_below, ours)
    assert np.array_equal(ours, _every_box_distance(a, b, radius, row, exact_below))  # to the bit
    numpy = capsule_distance(a, b, radius, box, exact_below).min(axis=1)
    np.testing.assert_allclose(ours, numpy, rtol=0.0, atol=1e-12)
    assert (ours < 0.0).any() and (ours > 0.05).any()


def test_box_bound_is_below_the_box_distance_and_often_close():
    """``box_bound`` never exceeds the signed distance along the segment (dense samples of the
    numpy box distance, and the golden section); it equals it where the segment is parallel to
    an axis outside the box's slab."""
    rng = np.random.default_rng(11)
    box = BOXES[1]
    _, row = obstacle_row(box)
    local = np.empty(6)
    t = np.linspace(0.0, 1.0, 2001)
    half = np.asarray(box.size) / 2.0
    for _ in range(300):
        local[:] = rng.uniform(-0.4, 0.4, 6)
        points = local[:3] + t[:, None] * (local[3:] - local[:3])
        excess = np.abs(points) - half
        dense = (np.linalg.norm(np.maximum(excess, 0.0), axis=1) + np.minimum(excess.max(axis=1), 0.0)).min()
        assert box_bound(local, row) <= dense + 1e-12
        assert box_bound(local, row) <= segment_box(local, row) + 1e-12
    local[:] = [0.0, 0.0, 0.5, 0.05, 0.02, 0.5]  # above the box: its distance is the height less the half size
    assert box_bound(local, row) == pytest.approx(0.5 - row[9], abs=1e-15)
    assert segment_box(local, row) == pytest.approx(0.5 - row[9], abs=1e-9)


@pytest.mark.parametrize("arm", ["ur5", "panda"])
def test_pair_minimum_equals_every_pair_computed(arm):
    robot, a, b, _ = _ends(arm, 600, 9)
    pairs = self_pairs(robot)
    ours = np.empty(len(a))
    pair_minimum(a, b, pairs.first, pairs.second, pairs.radius, ours)
    every = np.array([
        min(_capsules_apart(a, b, i, f, g) - radius for f, g, radius in zip(pairs.first, pairs.second, pairs.radius))
        for i in range(len(a))
    ])
    assert np.array_equal(ours, every)  # to the bit
    numpy = (segment_distance(a[:, pairs.first], b[:, pairs.first], a[:, pairs.second], b[:, pairs.second]) - pairs.radius).min(axis=1)
    np.testing.assert_allclose(ours, numpy, rtol=0.0, atol=1e-12)
    assert (ours < 0.0).any() and (ours > 0.0).any()


def test_span_points_equal_the_span_values():
    rng = np.random.default_rng(2)
    control = rng.uniform(-2.0, 2.0, (40, 4, 7))
    span = rng.integers(0, 40, 500)
    t = rng.random(500)
    ours = span_points(control, span, t, BASIS)
    theirs = np.array([span_values(control[s : s + 1], np.array([x]))[0][0, 0] for s, x in zip(span, t)])
    np.testing.assert_allclose(ours, theirs, rtol=0.0, atol=1e-13)


def _bounds_at_both_ends(pieces, robot, limits, kinds):
    """p, q, r, cap_start, cap_end of every interval, the rows computed at its start and again
    at its end, both ends laid out as points 2i and 2i + 1 of one grid (as before)."""
    start = bounds._rows(robot, limits, kinds, pieces.q0, pieces.dq0, pieces.ddq0)
    end = bounds._rows(robot, limits, kinds, pieces.q1, pieces.dq1, pieces.ddq1)
    k = len(pieces.ds)

    def interleave(x0, x1):
        out = np.empty((2 * k, *x0.shape[1:]))
        out[0::2], out[1::2] = x0, x1
        return out

    a, b, c, _, lower, upper, x_bound = (interleave(x0, x1) for x0, x1 in zip(start, end))
    s = np.zeros(2 * k)
    s[1::2] = pieces.ds
    zero = np.zeros_like(a)
    p, q, r, _, x_high, _ = interval_bounds(s, a, b, c, zero, a, b, c, zero, lower, upper, x_bound, x_bound, False, False, NOTHING_KEPT, NOTHING_BEFORE)
    cap_end = point_bounds(end[0], end[1], end[2], end[4], end[5], end[6])[4]
    return p[0::2], q[0::2], r[0::2], x_high[0::2], cap_end


@pytest.mark.parametrize("arm", ["ur5", "panda"])
def test_piece_bounds_compute_each_sample_once_and_equal_both_ends_computed(arm, monkeypatch):
    robot = robots.load(arm)
    start, goal = UR5 if arm == "ur5" else PANDA
    kinds = ("velocity", "acceleration", "torque")
    problem = build_problem(robot, robot.limits, kinds, start, goal, SearchOptions(roadmap_points=15, neighbors=4), True)
    pieces = problem.pieces
    sampled = []
    rows = bounds._rows

    def counted(robot, limits, kinds, q, dq, ddq):
        sampled.append(len(q))
        return rows(robot, limits, kinds, q, dq, ddq)

    monkeypatch.setattr(bounds, "_rows", counted)
    ours = bounds.piece_bounds(pieces, robot, robot.limits, kinds, NO_DEADLINE)
    assert sum(sampled) == len(pieces) * (INTERVALS + 1)  # not 2 INTERVALS per piece
    monkeypatch.setattr(bounds, "_rows", rows)
    theirs = _bounds_at_both_ends(pieces, robot, robot.limits, kinds)
    for mine, before in zip((ours.p, ours.q, ours.r, ours.cap_start, ours.cap_end), theirs):
        assert np.array_equal(mine, before)  # to the bit
    assert np.isfinite(ours.t2).any()


def test_pieces_hold_each_sample_once():
    """A piece's INTERVALS + 1 samples are held once (K, INTERVALS + 1, n_dof): the intervals'
    starts and ends read from them are those of ``curve.span_values`` on the pieces' control
    points, an interval's end the next one's start."""
    robot = robots.load("panda")
    start, goal = PANDA
    pieces = build_problem(robot, robot.limits, ("velocity",), start, goal, SearchOptions(roadmap_points=10, neighbors=4), True).pieces
    n = robot.dof
    assert pieces.q.shape == pieces.dq.shape == pieces.ddq.shape == (len(pieces), INTERVALS + 1, n)
    q, dq, ddq = span_values(pieces.control, np.linspace(0.0, 1.0, INTERVALS + 1))
    for held, computed in ((pieces.q, q), (pieces.dq, dq), (pieces.ddq, ddq)):
        assert np.array_equal(held, computed)
    starts, ends = pieces.q0.reshape(len(pieces), INTERVALS, n), pieces.q1.reshape(len(pieces), INTERVALS, n)
    assert np.array_equal(ends[:, :-1], starts[:, 1:])
    assert np.array_equal(pieces.dq1.reshape(len(pieces), INTERVALS, n)[:, -1], dq[:, -1])
