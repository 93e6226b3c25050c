"""The quickest monotone curve through a coordination diagram, its smoothing, and the pair
timed along a curve."""

from __future__ import annotations

import numpy as np
import pytest

from tests.planners.coordination.cells import FIRST, ur5_arm
from toptraj.planners.coordination import Cell
from toptraj.planners.coordination.curve import SmoothCurve, shortcut, shortest_curve, widened
from toptraj.planners.coordination.diagram import Diagram
from toptraj.planners.coordination.timing import pair_timing, solo_timing
from toptraj.planners.errors import InfeasiblePath

M = 100


def _diagram(blocked: np.ndarray) -> Diagram:
    s = np.linspace(0.0, 1.0, M + 1)
    return Diagram(s=s, distance=np.where(blocked, 0.0, 1.0), blocked=blocked, step1=np.zeros(M), step2=np.zeros(M))


def _cost(nodes: np.ndarray, dt: float) -> float:
    steps = np.diff(np.rint(nodes * M).astype(int), axis=0)
    assert set(map(tuple, steps)) <= {(1, 0), (0, 1), (1, 1)}
    return float(len(steps) * dt)


def test_around_a_square_the_quickest_curve_takes_21_single_steps():
    # D + H = D + V = 100 steps; to pass the square [40, 60]^2 below or beside it, i - j (or
    # j - i) must reach 21, so H = V >= 21 and the least time is (100 + 21) steps
    blocked = np.zeros((M + 1, M + 1), dtype=bool)
    blocked[40:61, 40:61] = True
    dt = np.full(M, 0.01)
    nodes = shortest_curve(_diagram(blocked), dt, dt)
    assert _cost(nodes, 0.01) == pytest.approx(1.21)
    assert not blocked[tuple(np.rint(nodes * M).astype(int).T)].any()
    free = _diagram(np.zeros((M + 1, M + 1), dtype=bool))
    assert _cost(shortest_curve(free, dt, dt), 0.01) == pytest.approx(1.0)


def test_the_smoothed_curve_is_monotone_and_stays_free():
    blocked = np.zeros((M + 1, M + 1), dtype=bool)
    blocked[30:71, 20:61] = True
    diagram = _diagram(blocked)
    dt = np.full(M, 0.01)
    curve = SmoothCurve(shortcut(diagram, shortest_curve(widened(diagram, 2), dt, dt)))
    s, ds, _ = curve.evaluate(np.linspace(0.0, 1.0, 5001))
    assert (np.diff(s, axis=0) >= -1e-12).all() and (ds >= 0.0).all()
    assert s[0] == pytest.approx([0.0, 0.0]) and s[-1] == pytest.approx([1.0, 1.0])
    assert diagram.free_at(s[:, 0], s[:, 1]).all()


def test_no_free_curve_is_infeasible_naming_how_far_it_gets():
    blocked = np.zeros((M + 1, M + 1), dtype=bool)
    blocked[50, :] = True  # s1 = 0.5 is closed whatever s2
    with pytest.raises(InfeasiblePath, match="cannot pass each other.*s1 = 0.49"):
        shortest_curve(_diagram(blocked), np.full(M, 0.01), np.full(M, 0.01))


def test_two_equal_arms_along_the_diagonal_take_one_arms_optimum():
    # the time-optimal timing is the same whatever the parameterization of one geometric path:
    # s1 = s2 along a B-spline parameterized unevenly near its ends is the arm's own path twice,
    # so the pair's duration converges to one arm's own (a wrong chain rule would not); the grid
    # error of the uneven parameterization is first order: extrapolated (Richardson) from two grids
    arm = ur5_arm(FIRST, [0.0, 0.0, 0.0])
    cell = Cell((arm, ur5_arm(FIRST, [0.0, 3.0, 0.0])), 0.02)
    curve = SmoothCurve(np.column_stack([np.linspace(0.0, 1.0, 11)] * 2))
    alone = solo_timing(arm, cell.kinds, intervals=800).duration
    coarse, fine = (pair_timing(cell, curve, intervals=n).duration for n in (800, 1600))
    assert fine - alone == pytest.approx((coarse - alone) / 2.0, rel=0.1)
    assert 2.0 * fine - coarse == pytest.approx(alone, rel=3e-4)
