"""The two ur5 of the shipped cell example served at every clearance some timing keeps: the
diagram's blocked region bounded from the cells' corners and refined where only the margin
blocks it (not the grid step's whole motion around each node), the answer checked by coal; and
a clearance above what any timing can keep still refused."""

from __future__ import annotations

import re

import numpy as np
import pytest

from tests.planners.coordination.cells import facing_cell
from tests.planners.coordination.independent import coal_distance
from toptraj.planners.coordination import coordinate
from toptraj.planners.coordination.diagram import Diagram, widest_coordination
from toptraj.planners.errors import InfeasiblePath
from toptraj.service.problems import detail


def _coal_min(cell, schedule, samples: int) -> float:
    t = np.linspace(0.0, schedule.duration, samples + 1)
    (q1, _, _), (q2, _, _) = schedule.states(cell, t)
    return min(coal_distance(cell, a, b) for a, b in zip(q1, q2))


@pytest.mark.parametrize("clearance", [0.05, 0.1, 0.11])
def test_a_clearance_some_timing_keeps_is_served_and_kept_by_coal(clearance):
    # at clearance 0.028 the cell is timed with the arms 0.111 m apart or more (one arm waiting at its
    # start while the other passes): 0.05, 0.1 and 0.11 are kept too
    cell = facing_cell(clearance=clearance)
    found = coordinate(cell)
    assert found.clearance.bound >= clearance
    assert _coal_min(cell, found.schedule, 400) >= clearance


def test_a_clearance_no_timing_keeps_is_refused():
    # every monotone curve from (0, 0) to (1, 1) of the diagram crosses the line s1 + s2 = 1.4, so
    # no timing keeps the arms farther apart than the largest distance on it (coal, 401 samples;
    # between samples each arm moves about 5 mm: 0.03 m above it is out of reach)
    cell = facing_cell()
    s1 = np.linspace(0.4, 1.0, 401)
    q1, q2 = cell.arms[0].path.evaluate(s1).q, cell.arms[1].path.evaluate(1.4 - s1).q
    reach = max(coal_distance(cell, a, b) for a, b in zip(q1, q2))
    assert reach < 0.25
    with pytest.raises(InfeasiblePath, match="no timing keeps the arms apart") as refused:
        coordinate(facing_cell(clearance=reach + 0.03))
    # it names the closest approach of the coordination that keeps the arms farthest apart (on
    # the diagram's grid; no more than the largest distance on that line) and the clearance to
    # ask for instead; asked for, it is served and kept (coal, 401 samples)
    error = refused.value
    assert 0.0 < error.distance <= reach and error.clearance == reach + 0.03
    worded = detail(error)  # as the service words it
    assert error.arms == (0, 1) and all(link in worded for link in error.links) and "arms[1] at s = " in worded
    room = float(re.search(r"lower clearance to ([\d.e-]+) m or less", worded).group(1))
    assert error.distance - 0.006 < room <= error.distance - 0.005
    found = coordinate(facing_cell(clearance=room))
    assert found.clearance.bound >= room
    assert _coal_min(facing_cell(clearance=room), found.schedule, 400) >= room


def _all_monotone_least(distance: np.ndarray) -> float:
    """The largest least distance over every monotone path of the grid, by enumeration."""
    n = distance.shape[0]

    def walk(i, j, least):
        least = min(least, distance[i, j])
        if (i, j) == (n - 1, n - 1):
            return least
        steps = [(i + di, j + dj) for di, dj in ((1, 0), (0, 1), (1, 1)) if i + di < n and j + dj < n]
        return max(walk(a, b, least) for a, b in steps)

    return walk(0, 0, np.inf)


def test_the_widest_coordination_is_the_best_of_every_monotone_path():
    rng = np.random.default_rng(7)
    for _ in range(20):
        distance = rng.uniform(0.0, 1.0, (6, 6))
        diagram = Diagram(np.linspace(0.0, 1.0, 6), distance, np.zeros((6, 6), dtype=bool), np.zeros(5), np.zeros(5))
        widest, i, j = widest_coordination(diagram)
        assert widest == _all_monotone_least(distance) and distance[i, j] == widest


def test_the_clearance_check_in_chunks_finds_what_one_pass_finds(monkeypatch):
    """The samples are checked ``CHUNK`` at a time, the chunks sharing their ends: the closest
    approach, its instant and links, and the bound between samples are those of one pass."""
    from toptraj.planners.coordination import verify

    cell = facing_cell(clearance=0.05)
    schedule = coordinate(cell).schedule
    whole = verify.schedule_clearance(cell, schedule)
    monkeypatch.setattr(verify, "CHUNK", 7)
    chunked = verify.schedule_clearance(cell, schedule)
    assert chunked == whole and whole.samples > 7 * 10


def test_long_paths_of_arms_far_apart_are_checked_and_answered():
    """Two ur5s swinging every joint through 12 rad, 3 m apart: 33,601 samples, which the check
    refused (at most 20,000) after seconds of work; checked in chunks, the cell is answered and
    coal keeps its clearance."""
    from tests.planners.coordination.cells import ur5_arm
    from toptraj.planners.coordination import Cell

    path = [[-6.0, -0.5, 0.5, -6.0, -6.0, -6.0], [6.0, -0.6, 0.6, 6.0, 6.0, 6.0]]
    cell = Cell((ur5_arm(path, [0.0, 0.0, 0.0]), ur5_arm(path, [3.0, 0.0, 0.0])), 0.02)
    found = coordinate(cell)
    assert found.clearance.samples > 20_000 and found.clearance.bound >= 0.02
    assert _coal_min(cell, found.schedule, 200) >= 0.02
