"""Three arms in one cell by prioritized planning (``coordination.prioritized``): the two ur5
facing each other with crossing paths and a third at the table's side reaching across the same
middle. Every pair keeps its clearance by an independent distance check (coal); the cell is
never slower than the arms one after the other, nor quicker than the slowest arm's own optimum;
every arm's limits hold on a dense resampling; and every pairwise diagram is blocked where the
arms meet."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from tests.planners.coordination.cells import FIRST, facing_cell, ur5_arm
from tests.planners.coordination.independent import coal_distance
from toptraj.planners.coordination import Cell, coordinate
from toptraj.planners.coordination.timing import Schedule, SoloMotion, solo_timing
from toptraj.planners.errors import InfeasiblePath

#: A quarter turn about z: the third base faces -y, towards the middle of the table.
QUARTER = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def three():
    pair = facing_cell()
    cell = Cell(pair.arms + (ur5_arm(FIRST, [0.6, 1.1, 0.0], QUARTER),), pair.clearance)
    return cell, coordinate(cell)


def _pair_minimum(cell: Cell, schedule: Schedule, a: int, b: int, samples: int) -> float:
    states = schedule.states(cell, np.linspace(0.0, schedule.duration, samples + 1))
    pair = Cell((cell.arms[a], cell.arms[b]), cell.clearance)
    return min(coal_distance(pair, qa, qb) for qa, qb in zip(states[a][0], states[b][0]))


def test_every_pair_keeps_the_clearance_by_an_independent_check(three):
    cell, found = three
    simultaneous = Schedule(tuple(SoloMotion(solo_timing(arm, cell.kinds)) for arm in cell.arms), "simultaneous")
    met = [_pair_minimum(cell, simultaneous, a, b, 150) < cell.clearance for a, b in itertools.combinations(range(3), 2)]
    assert sum(met) >= 2  # at once, the third arm meets at least one other, and the facing pair each other
    for a, b in itertools.combinations(range(3), 2):
        assert _pair_minimum(cell, found.schedule, a, b, 300) >= cell.clearance
    assert found.clearance.bound >= cell.clearance and set(found.diagrams) == {(0, 1), (0, 2), (1, 2)}
    assert all(diagram.blocked.any() for diagram in found.diagrams.values())


def test_never_slower_than_one_arm_after_the_other_nor_quicker_than_the_slowest(three):
    _, found = three
    assert max(found.solo) <= found.schedule.duration <= sum(found.solo) * 1.005
    assert found.schedule.kind.startswith("prioritized") and found.time_lost > 0.05


def test_every_arms_limits_hold_on_a_dense_resampling(three):
    cell, found = three
    schedule = found.schedule
    t = np.linspace(0.0, schedule.duration, 20_001)
    for arm, (q, qd, qdd) in zip(cell.arms, schedule.states(cell, t)):
        assert (np.abs(qd) <= arm.limits.velocity * 1.005).all()
        assert (np.abs(qdd) <= arm.limits.acceleration * 1.005).all()
        assert np.abs(q[0] - arm.path.evaluate(np.zeros(1)).q[0]).max() < 1e-12
        assert np.abs(q[-1] - arm.path.evaluate(np.ones(1)).q[0]).max() < 1e-12


#: The third arm reaching into the table's middle at its start and its end (only its wrist turns):
#: the facing pair sweeps through where it rests.
REACHING = [[0.0, -0.6, 0.6, 0.0, 0.3, 0.0], [0.0, -0.6, 0.6, 0.0, 1.0, 0.0], [0.0, -0.6, 0.6, 0.0, 1.7, 0.0]]


def test_an_arm_resting_where_the_others_pass_is_refused_naming_the_pairs_the_links_and_where():
    """No order lets the facing pair pass the third arm, which rests in their way at its start and
    its end: the refusal names, for each of the two pairs, the closest approach of either order,
    which coal confirms closer than the clearance; moved 0.7 m back, the third arm lets them pass."""
    pair = facing_cell()
    cell = Cell(pair.arms + (ur5_arm(REACHING, [0.6, 1.1, 0.0], QUARTER),), pair.clearance)
    with pytest.raises(InfeasiblePath, match="no order of the arms") as refused:
        coordinate(cell)
    turns = refused.value.turns
    assert refused.value.rule == "no_order_of_arms"
    assert {(t.moving, t.resting, t.rests_at) for t in turns} == {(0, 2, "start"), (0, 2, "end"), (1, 2, "start"), (1, 2, "end")}
    assert {(t.first, t.moving, t.rests_at) for t in turns} == {(0, 0, "start"), (2, 0, "end"), (1, 1, "start"), (2, 1, "end")}
    assert "with arm 0 first, arm 0's link 'forearm_link' at s = " in refused.value.detail
    assert "overlaps link 'forearm_link' of arm 2 resting at its start by " in refused.value.detail
    for turn in turns:
        assert turn.distance < cell.clearance and 0.0 < turn.s < 1.0
        assert turn.moving_link in cell.arms[turn.moving].link_names() and turn.resting_link in cell.arms[turn.resting].link_names()
        moving, resting = cell.arms[turn.moving], cell.arms[turn.resting]
        q_moving = moving.path.evaluate(np.array([turn.s])).q[0]
        q_resting = resting.path.evaluate(np.array([0.0 if turn.rests_at == "start" else 1.0])).q[0]
        assert coal_distance(Cell((moving, resting), cell.clearance), q_moving, q_resting) == pytest.approx(turn.distance, abs=1e-6)
    moved = Cell(pair.arms + (ur5_arm(REACHING, [0.6, 1.8, 0.0], QUARTER),), pair.clearance)
    assert coordinate(moved).clearance.bound >= cell.clearance


class _Turns:
    """A pair's diagram reduced to which arm may go first (``_orders`` reads its borders)."""

    def __init__(self, first_may: bool, second_may: bool):
        self.s = np.linspace(0.0, 1.0, 5)
        self.first_may, self.second_may = first_may, second_may

    def free_at(self, s_a, s_b):
        s_a, s_b = np.broadcast_arrays(np.asarray(s_a, dtype=float), np.asarray(s_b, dtype=float))
        # first arm first: its column s_b = 0 and then the row s_a = 1; second first: row s_a = 0, column s_b = 1
        if np.all(s_b == 0.0) or (np.all(s_a == 1.0) and not np.all(s_b == 1.0)):
            return np.full(s_a.shape, self.first_may)
        return np.full(s_a.shape, self.second_may)


def test_pairs_that_take_turns_only_in_circular_orders_are_named_as_that_circle():
    """Four arms in a ring: each pair can take turns, but arm 0 only before arm 1, 1 before 2, 2
    before 0 (and arm 3 either way): no order serves, and the refusal names the circle instead of
    nothing."""
    from toptraj.planners.coordination.prioritized import _orders, _precedence_cycle
    from toptraj.service.problems import detail

    assert _orders(_Turns(True, False)) == (True, False) and _orders(_Turns(False, True)) == (False, True)
    diagrams = {(0, 1): _Turns(True, False), (1, 2): _Turns(True, False), (0, 2): _Turns(False, True),
                (0, 3): _Turns(True, True), (1, 3): _Turns(True, True), (2, 3): _Turns(True, True)}
    assert _precedence_cycle(diagrams, 4) == (0, 1, 2, 0)
    diagrams[(0, 2)] = _Turns(True, False)  # 0 before 2 as well: 0, 1, 2, 3 serves
    assert _precedence_cycle(diagrams, 4) == ()
    refused = InfeasiblePath("no order", rule="no_order_of_arms", turns=(), clearance=0.02, cycle=(0, 1, 2, 0))
    assert detail(refused).endswith(
        "each pair of arms can take turns, but only in orders that go round in a circle: arms[0] before arms[1] before "
        "arms[2] before arms[0] (each of these can pass the next only by moving first, while the next rests at its start); "
        "move the base of one of them apart, or change its path so that it can also wait for the next one"
    )
