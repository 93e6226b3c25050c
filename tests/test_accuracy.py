"""Accuracy as stated: the default phase_plane answer is at most 0.1 % above the converged
time-optimal duration (TOPP-RA on 20,000 intervals), on seeded random spline paths of ur5,
panda and the two-link paper arms. ``benchmarks/accuracy.py`` runs the larger study."""

from __future__ import annotations

import numpy as np
import pytest

import robots
from benchmarks.accuracy import KINDS, converged_duration, random_waypoints
from planners import Timing, WaypointPath, plan
from planners.errors import InfeasiblePath


@pytest.mark.parametrize("name", ["ur5", "panda", "geering_2r", "yamamoto_2r"])
def test_default_durations_are_within_a_tenth_of_a_percent_of_the_converged_optimum(name):
    robot = robots.load(name)
    rng = np.random.default_rng(7)
    compared = 0
    for _ in range(3):
        waypoints = random_waypoints(robot, rng)
        try:
            reference = converged_duration(robot, waypoints)
        except InfeasiblePath:
            continue
        result = plan(robot, WaypointPath(waypoints), Timing(method="phase_plane", constraints=KINDS), dt=0.01)
        # Both are conservative discretizations of the same problem: the refined grid may
        # come out a hair below the 20,000-interval one, never far.
        assert 0.9995 <= result.duration / reference <= 1.001, (waypoints.tolist(), result.duration, reference)
        compared += 1
    assert compared >= 2
