"""Two ur5 facing each other across a table with crossing paths (issue 37): the timed pair
keeps its clearance by an independent distance check (coal), is never slower than one arm
after the other, equals the slower arm's own optimum when the arms never meet, and holds each
arm's limits on a dense resampling."""

from __future__ import annotations

import numpy as np
import pytest

from tests.planners.coordination.cells import FIRST, SECOND, TURNED, facing_cell, ur5_arm
from tests.planners.coordination.independent import coal_distance
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, build_problem
from toptraj.planners.coordination import Cell, coordinate
from toptraj.planners.coordination.coordinate import curve_schedule
from toptraj.planners.coordination.timing import Schedule, SoloMotion, solo_timing
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.plan import plan
from toptraj.planners.problem.requests import WaypointPath

KINDS = ("velocity", "acceleration")


@pytest.fixture(scope="module")
def crossing():
    cell = facing_cell()
    return cell, coordinate(cell)


def _coal_min(cell, schedule, samples: int) -> float:
    t = np.linspace(0.0, schedule.duration, samples + 1)
    (q1, _, _), (q2, _, _) = schedule.states(cell, t)
    return min(coal_distance(cell, a, b) for a, b in zip(q1, q2))


def test_crossing_arms_keep_the_clearance_by_an_independent_check(crossing):
    cell, found = crossing
    # the arms' own optima at once would collide: coordination is needed
    both = Schedule(tuple(SoloMotion(m.scaling) for m in _solo_motions(cell)), "simultaneous")
    assert _coal_min(cell, both, 200) < cell.clearance
    assert _coal_min(cell, found.schedule, 400) >= cell.clearance
    assert found.clearance.bound >= cell.clearance and found.time_lost > 0.05


def _solo_motions(cell):
    return [SoloMotion(solo_timing(arm, KINDS)) for arm in cell.arms]


def test_never_slower_than_one_arm_after_the_other(crossing):
    cell, found = crossing
    one_after_the_other = _planned(FIRST) + _planned(SECOND)
    assert found.schedule.duration <= one_after_the_other * 1.005
    assert found.schedule.duration >= max(found.solo) - 1e-9


def _planned(waypoints) -> float:
    """The arm's own optimum by the project's planner (phase plane, gate included)."""
    result = plan(build_problem(robots.load("ur5"), WaypointPath(np.array(waypoints)), METHODS["phase_plane"], limits=LimitRequest(kinds=KINDS)))
    return result.duration


def test_arms_that_never_meet_take_the_slower_arms_own_optimum():
    short = [[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.6, -1.0, 1.4, -0.5, 0.6, 0.3]]
    far = Cell((ur5_arm(FIRST, [0.0, 0.0, 0.0]), ur5_arm(short, [4.0, 0.0, 0.0], TURNED)), 0.02)
    found = coordinate(far)
    slower = max(_planned(FIRST), _planned(short))
    assert 0.0 <= found.time_lost < 5e-3 * slower
    assert found.schedule.duration == pytest.approx(slower, rel=5e-3)
    assert found.schedule.kind == "simultaneous"


def test_each_arms_limits_hold_on_a_dense_resampling(crossing):
    cell, found = crossing
    schedule = found.schedule
    t = np.linspace(0.0, schedule.duration, 40_001)
    for arm, (q, qd, qdd) in zip(cell.arms, schedule.states(cell, t)):
        assert (np.abs(qd) <= arm.limits.velocity * 1.005).all()
        assert (np.abs(qdd) <= arm.limits.acceleration * 1.005).all()
        # the samples are one motion: velocities integrate to the positions
        step = t[1] - t[0]
        assert np.abs(np.diff(q, axis=0) - (qd[1:] + qd[:-1]) / 2.0 * step).max() < 1e-5
        assert np.abs(q[0] - arm.path.evaluate(np.zeros(1)).q[0]).max() < 1e-12
        assert np.abs(q[-1] - arm.path.evaluate(np.ones(1)).q[0]).max() < 1e-12


def test_arms_that_collide_at_their_start_are_refused_naming_the_links():
    close = facing_cell(distance=0.1)  # the bases overlap
    with pytest.raises(InvalidRequest) as refused:
        coordinate(close)
    error = refused.value
    assert (error.rule, error.field, error.first, error.second) == ("arms_collide_at_start", "arms[1]", 0, 1)
    assert all(isinstance(link, str) and link for link in error.links)
    assert error.distance < error.clearance


def test_a_fifth_arm_is_refused_naming_the_bound():
    cell = facing_cell()
    far = tuple(ur5_arm(FIRST, [0.0, 3.0 * k, 0.0]) for k in range(1, 4))
    with pytest.raises(InvalidRequest) as refused:
        coordinate(Cell(cell.arms + far, cell.clearance))
    error = refused.value
    assert (error.rule, error.value, error.fewest, error.most) == ("too_many_arms", 5, 2, 4)


def test_the_coordinated_curve_keeps_clearance_and_limits(crossing):
    # the curve candidate on its own (on the example a late start is quicker, and is chosen)
    cell, found = crossing
    solo = [solo_timing(arm, KINDS) for arm in cell.arms]
    schedule = curve_schedule(cell, found.diagram, solo, NO_DEADLINE)
    assert schedule is not None and schedule.kind == "coordinated"
    assert max(found.solo) < found.schedule.duration <= schedule.duration < sum(found.solo)
    assert _coal_min(cell, schedule, 300) >= cell.clearance
    t = np.linspace(0.0, schedule.duration, 20_001)
    for arm, (_, qd, qdd) in zip(cell.arms, schedule.states(cell, t)):
        assert (np.abs(qd) <= arm.limits.velocity * 1.005).all()
        assert (np.abs(qdd) <= arm.limits.acceleration * 1.005).all()
