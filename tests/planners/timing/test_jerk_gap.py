"""The gap ``jerk_limited`` states (``Accuracy.relative_gap``) against its distance from a
converged optimum computed independently of the answer, on the ur5 example
``examples/ur5_jerk_limited.json``.

The reference is the same discretization (``toptraj.planners.timing.jerk.program``) on grids
four and eight times as fine as the answer's default grid (every interval halved but the two
at rest, which hold the constant-jerk phase exactly: ``toptraj.planners.timing.jerk.accuracy.refined``),
each sequence of LPs run to a relative gain of 1e-10, and extrapolated to zero interval with
the first-order convergence observed there (the differences halve with each halving:
3.4e-4, 1.7e-4, 7.8e-5 s): T* = 2 T(h/8) - T(h/4).
"""

from __future__ import annotations

import functools
import json

import numpy as np

from tests.paths import ROOT
from toptraj import robots
from toptraj.planners import METHODS, WaypointPath, build_problem, plan
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.problem import LimitRequest, Sampling
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.timing.base import AT_REST
from toptraj.planners.timing.jerk.accuracy import refined
from toptraj.planners.timing.jerk.method import JerkLimitedMethod
from toptraj.planners.timing.jerk.scaling import JerkTimeScaling

EXAMPLE = json.loads((ROOT / "examples" / "ur5_jerk_limited.json").read_text())
#: The issue's bound on the distance of the answer from the optimum.
WITHIN = 1e-3


@functools.cache
def _converged_optimum() -> float:
    """T* from the grids 4 and 8 times as fine as the default one (module docstring)."""
    robot, limits, waypoints = _example()
    path = make_path(robot, WaypointPath(waypoints))
    kinds = tuple(EXAMPLE["timing"]["constraints"])
    constraints = build_path_constraints(path, robot, limits, kinds, path_grid(path))
    # The LPs on the finer grids start from the method's own solution on its default grid
    # (the same discretization; the limit they converge to does not depend on where they start).
    start = JerkLimitedMethod(polish=False, max_refinements=0).solve(constraints)
    assert isinstance(start, JerkTimeScaling)  # a spline path: no closed form, no polish
    constraints = constraints.with_points(np.setdiff1d(start.s, constraints.s))
    method = JerkLimitedMethod(tolerance=1e-10, max_iterations=300, polish=False)
    durations = []
    for _ in range(3):
        constraints = refined(constraints, AT_REST)
        start = method._grid_solution(constraints, AT_REST, NO_DEADLINE, start=start)
        durations.append(start.duration)
    assert len(start.s) - 1 >= 1500  # eight times the default grid
    return 2.0 * durations[-1] - durations[-2]


def _example():
    robot = robots.load(EXAMPLE["robot"])
    limits = robot.limits.with_request(scales={"jerk": EXAMPLE["timing"]["limits"]["jerk_scale"]})
    return robot, limits, np.array(EXAMPLE["path"]["waypoints"])


def _asked() -> LimitRequest:
    """The example's constraints and jerk scale, as its request asks them."""
    return LimitRequest(kinds=tuple(EXAMPLE["timing"]["constraints"]), scales={"jerk": EXAMPLE["timing"]["limits"]["jerk_scale"]})


def test_the_stated_gap_of_the_ur5_jerk_example_holds_against_the_converged_optimum():
    robot, _, waypoints = _example()
    answer = plan(build_problem(robot, WaypointPath(waypoints), METHODS["jerk_limited"], limits=_asked(),
                                sampling=Sampling(dt=EXAMPLE["output"]["dt"])))
    optimum = _converged_optimum()
    actual = (answer.duration - optimum) / optimum
    assert answer.accuracy is not None and answer.accuracy.relative_gap is not None
    stated = answer.accuracy.relative_gap
    assert -1e-4 <= actual <= stated, (answer.duration, optimum, actual, stated)
    assert actual <= WITHIN


def test_a_named_grid_finer_than_the_constant_jerk_phase_answers_within_the_bound_of_the_optimum():
    """On a named grid of 2,000 intervals, finer than the phase of constant jerk from rest, the
    points within half of it are dropped (``toptraj.planners.timing.jerk.rest_phase.opened``): with
    them, the answer was 0.39 % above the optimum."""
    robot, _, waypoints = _example()
    answer = plan(build_problem(robot, WaypointPath(waypoints), METHODS["jerk_limited"], limits=_asked(), grid=2000,
                                sampling=Sampling(dt=EXAMPLE["output"]["dt"])))
    optimum = _converged_optimum()
    assert -1e-4 <= (answer.duration - optimum) / optimum <= WITHIN
