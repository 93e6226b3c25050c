"""A time law whose acceleration jumps (cubic, trapezoidal) has an infinite jerk at each jump:
its answer reports no finite jerk peak (which would read as the motion's) and says why; a law
with a continuous acceleration keeps its jerk peak, which equals the jerk recomputed from its
samples by differences."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import LimitRequest, WaypointPath, build_problem, plan
from toptraj.planners.problem.problem import Sampling
from toptraj.planners.problem.time_law import TimeLaw

WAYPOINTS = np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]])


def _plan(law: str):
    arm = robots.load("ur5")
    problem = build_problem(
        arm, WaypointPath(WAYPOINTS), TimeLaw(law).method(),
        limits=LimitRequest(kinds=("velocity", "acceleration")), sampling=Sampling(dt=0.001),
    )
    return arm, plan(problem)


@pytest.mark.parametrize(("law", "jumps"), [("cubic", "0, 1"), ("trapezoidal", "0, 0.3333, 0.6667, 1")])
def test_a_law_whose_acceleration_jumps_reports_no_finite_jerk(law, jumps):
    _, result = _plan(law)
    assert "jerk" not in result.peak_utilization
    said = [note for note in map(str, result.warnings) if "jerk is infinite" in note]
    assert len(said) == 1 and f"jumps at tau = {jumps}" in said[0]


def test_a_law_with_a_continuous_acceleration_keeps_its_jerk_peak():
    arm, result = _plan("quintic")
    assert not [note for note in map(str, result.warnings) if "jerk is infinite" in note]
    samples = result.samples
    jerk = np.diff(samples.qdd, axis=0) / np.diff(samples.t)[:, None]  # differences of the samples
    peak_from_samples = np.max(np.abs(jerk), axis=0) / arm.limits.jerk
    np.testing.assert_allclose(result.peak_utilization["jerk"], peak_from_samples, rtol=2e-2)
