"""When the local optimization's rounds end (``toptraj.planners.generators.search.local._rounds``):
after a round that finds nothing faster right after one that did, and never because of a round
whose path fails the dense checks."""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.generators.search import local

START, GOAL = np.zeros(2), np.array([0.76, 0.0])


def _free_motion(monkeypatch, unclear_at: int | None = None):
    """The Geering arm's free motion from its straight seed; with ``unclear_at``, the round of
    that many control points is made to fail the dense checks."""
    robot = robots.load("geering_2r")
    checked = local._clear

    def clear(path, *args):
        if unclear_at is not None and len(path.control) == unclear_at:
            return False, None
        return checked(path, *args)

    monkeypatch.setattr(local, "_clear", clear)
    return local.optimize_locally(robot, np.array([START, GOAL]), robot.limits, ("torque",))


def test_a_first_round_above_the_seed_does_not_end_the_rounds(monkeypatch):
    optimum = _free_motion(monkeypatch)
    rounds = optimum.statistics.rounds
    # the 4-point round ends above the fitted seed (its objective on the optimization grid is
    # lower); the rounds after it gain, each, until they gain less than 0.1 % twice
    assert rounds[0].duration > optimum.statistics.seed_duration
    assert [r.control_points for r in rounds][:3] == [4, 5, 7]
    assert optimum.statistics.stopped == "converged"
    assert optimum.duration < 0.98  # the paper's 0.9755 s within 0.5 %


def test_a_round_that_fails_the_dense_checks_does_not_end_the_rounds(monkeypatch):
    optimum = _free_motion(monkeypatch, unclear_at=7)
    rounds = optimum.statistics.rounds
    counts = [r.control_points for r in rounds]
    assert 7 in counts and not rounds[counts.index(7)].clear
    assert counts[counts.index(7) + 1] == 9  # the rounds go on after it
    assert optimum.duration < 0.98
