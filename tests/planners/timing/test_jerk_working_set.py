"""The jerk-limited timing's linear programs over a working set of their rows
(``toptraj.planners.timing.jerk.working_set``) and its batched durations
(``toptraj.planners.timing.jerk.scaling.interval_times``), each against an independent computation: the
whole LP solved by HiGHS from scratch, and the time integral of ds / sd by adaptive quadrature."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from toptraj import robots
from toptraj.planners import METHODS, BoundaryStates, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.timing.base import AT_REST
from toptraj.planners.timing.jerk import working_set
from toptraj.planners.timing.jerk.accuracy import extrapolated_errors
from toptraj.planners.timing.jerk.program import RestrictedProgram
from toptraj.planners.timing.jerk.rest_phase import graded
from toptraj.planners.timing.jerk.scaling import JerkTimeScaling, interval_times
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

#: The path of examples/ur5_jerk_limited.json.
EXAMPLE_WAYPOINTS = np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]])
KINDS = ("velocity", "acceleration", "torque", "jerk")


def _example_program():
    arm = robots.load("ur5")
    path = make_path(arm, WaypointPath(EXAMPLE_WAYPOINTS))
    limits = arm.limits.with_request(scales={"jerk": 0.5})
    constraints = graded(build_path_constraints(path, arm, limits, KINDS, path_grid(path)), AT_REST)
    reference = PhasePlaneMethod(max_refinements=0).solve(constraints)
    x_ref = reference.speed_at(constraints.s) ** 2
    return RestrictedProgram(constraints, AT_REST, x_ref), x_ref


def _full_lp(objective, matrix, lower, upper, low, high):
    """The whole LP, every row, by HiGHS from scratch: (objective value, column values)."""
    import highspy

    solver = highspy.Highs()
    solver.setOptionValue("output_flag", False)
    solver.setOptionValue("primal_feasibility_tolerance", 1e-10)
    columns = matrix.tocsc()
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = columns.shape[1], columns.shape[0]
    lp.col_cost_, lp.col_lower_, lp.col_upper_ = objective, low, high
    lp.row_lower_, lp.row_upper_ = lower, upper
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = columns.indptr, columns.indices, columns.data
    solver.passModel(lp)
    solver.run()
    assert solver.getModelStatus() == highspy.HighsModelStatus.kOptimal
    values = np.asarray(solver.getSolution().col_value)
    return float(objective @ values), values


def test_the_working_set_reaches_the_whole_lps_optimum_over_a_fifth_of_its_rows(monkeypatch):
    """The restricted LPs of the ur5 example (the first two of its sequence): the working set's
    optimum has the objective of the whole LP solved from scratch (to 1e-9), holds every row
    (to HiGHS's tolerance of 1e-10), and was found over at most a fifth of the rows."""
    captured = []
    solve = working_set.WorkingSetLP.solve

    def spy(self, objective, matrix, lower, upper, low, high, seed=None):
        values = solve(self, objective, matrix, lower, upper, low, high, seed)
        captured.append(((objective, matrix, lower, upper, low, high), values, self.rows.size))
        return values

    monkeypatch.setattr(working_set.WorkingSetLP, "solve", spy)
    program, x_ref = _example_program()
    x, _ = program.solve_restricted(x_ref, seed=(x_ref, 0.5 * np.gradient(x_ref, program.constraints.s)))
    program.solve_restricted(x)
    assert len(captured) == 2
    for arguments, values, rows in captured:
        objective, matrix, lower, upper = arguments[:4]
        expected, _ = _full_lp(*arguments)
        assert float(objective @ values) == pytest.approx(expected, rel=1e-9, abs=1e-12)
        activity = matrix @ values
        assert np.all(activity <= upper + 2e-10) and np.all(activity >= lower - 2e-10)
        assert rows <= 0.2 * matrix.shape[0]


@pytest.mark.parametrize("rest_start, rest_end", [(True, True), (False, True), (False, False)])
def test_batched_interval_times_equal_adaptive_quadrature(rest_start, rest_end):
    """Each of three motions on one grid, u linear and x quadratic on each interval (an
    interval at rest holding constant path jerk): the batched interval times equal the integral
    of ds / sqrt(x(s)) by scipy's adaptive quadrature (the constant-jerk time at rest), to
    1e-9, and equal ``JerkTimeScaling``'s own."""
    rng = np.random.default_rng(7)
    s = np.concatenate([[0.0], np.sort(rng.uniform(0.05, 0.95, 9)), [1.0]])
    h = np.diff(s)
    motions = []
    for _ in range(3):
        u = rng.uniform(-0.2, 0.2, len(s))
        x = np.empty(len(s))
        x[0] = 0.0 if rest_start else rng.uniform(0.8, 1.2)
        if rest_start:
            u[0] = 0.0
            x[1] = rng.uniform(0.8, 1.2)
            u[1] = 2.0 * x[1] / (3.0 * h[0])
        for i in range(1 if rest_start else 0, len(s) - 1):
            x[i + 1] = x[i] + (u[i] + u[i + 1]) * h[i]
        if rest_end:
            x[-1], u[-1] = 0.0, 0.0
        assert x[1:-1].min() > 0.1
        motions.append((x, u))
    x = np.array([m[0] for m in motions])
    u = np.array([m[1] for m in motions])
    times = interval_times(s, x, u, rest_start, rest_end)
    for m in range(3):
        timing = JerkTimeScaling(s, np.sqrt(x[m]), u=u[m], rest_start=rest_start, rest_end=rest_end)
        assert times[m] == pytest.approx(timing.interval_times, rel=1e-12)
        for i in range(len(h)):
            if (i == 0 and rest_start) or (i == len(h) - 1 and rest_end):
                sigma = (2.0 / 9.0) * x[m, 1 if i == 0 else -2] ** 1.5 / h[i] ** 2
                expected = np.cbrt(6.0 * h[i] / sigma)  # s = sigma t^3 / 6 from or to rest
            else:
                w = (u[m, i + 1] - u[m, i]) / h[i]

                def speed(r, m=m, i=i, w=w):
                    return np.sqrt(max(x[m, i] + 2.0 * u[m, i] * r + w * r * r, 0.0))

                expected = quad(lambda r, speed=speed: 1.0 / speed(r), 0.0, h[i], epsabs=0.0, epsrel=1e-12)[0]
            assert times[m, i] == pytest.approx(expected, rel=1e-9)


def test_a_straight_ur5_line_from_motion_is_ruckig_through_the_lps_and_the_polish():
    """A straight joint line entered at speed (no closed form: the LPs over their working sets,
    then the polish) against ruckig's phase-synchronized optimum from the same state: within
    the 3e-6 the method claims on straight lines, and never shorter."""
    from ruckig import InputParameter, Ruckig, Synchronization, Trajectory

    arm = robots.load("ur5")
    start, goal = np.array([-0.8, -1.6, 1.2, -0.4, 0.5, 0.2]), np.array([0.9, -0.7, 0.3, 0.6, -0.4, 1.1])
    limits = arm.limits.with_request(scales={"jerk": 0.6})
    direction = (goal - start) / np.abs(goal - start).max()
    entry = 0.3 * float(np.min(limits.velocity / np.abs(direction)))
    result = plan(build_problem(arm, WaypointPath(np.array([start, goal])), METHODS["jerk_limited"], limits=LimitRequest(kinds=("velocity", "acceleration", "jerk"), scales={"jerk": 0.6}), boundary=BoundaryStates(start_velocity=entry * direction), sampling=Sampling(dt=0.01)))
    inputs = InputParameter(arm.dof)
    inputs.current_position, inputs.target_position = start.tolist(), goal.tolist()
    inputs.current_velocity = (entry * direction).tolist()
    inputs.max_velocity, inputs.max_acceleration = limits.velocity.tolist(), limits.acceleration.tolist()
    inputs.max_jerk = limits.jerk.tolist()
    inputs.synchronization = Synchronization.Phase
    trajectory = Trajectory(arm.dof)
    Ruckig(arm.dof).calculate(inputs, trajectory)
    assert result.duration == pytest.approx(trajectory.duration, rel=3e-6)
    assert result.duration >= trajectory.duration * (1 - 1e-9)



def test_a_fine_grid_starts_from_the_grids_below_it(monkeypatch):
    """ur5's example path on 800 intervals: the LPs of every grid start from the solution on
    every other point of it, down to the coarsest (at most twice ``SEED_INTERVALS``), which
    alone starts from the jerk-free optimum; the answer's gap is extrapolated from its second
    grid's duration, its own and that on its grid halved (solved for the estimate only, started
    from the answer), each sequence converged from its own start."""
    from toptraj.planners.timing.jerk import method as jerk_method

    calls = []
    grid_solution = jerk_method.JerkLimitedMethod._grid_solution

    def spy(self, constraints, boundary, deadline, start=None, tolerance=None):
        result = grid_solution(self, constraints, boundary, deadline, start=start, tolerance=tolerance)
        calls.append((len(constraints.s) - 1, None if start is None else len(start.s) - 1, result.duration))
        return result

    monkeypatch.setattr(jerk_method.JerkLimitedMethod, "_grid_solution", spy)
    arm = robots.load("ur5")
    path = make_path(arm, WaypointPath(EXAMPLE_WAYPOINTS))
    limits = arm.limits.with_request(scales={"jerk": 0.5})
    constraints = build_path_constraints(path, arm, limits, KINDS, path_grid(path, 800))
    answer = jerk_method.JerkLimitedMethod(max_refinements=0, polish=False).solve(constraints)
    sizes = [size for size, _, _ in calls]
    assert sizes == sorted(sizes) and len(sizes) >= 4
    assert calls[0][1] is None and sizes[0] <= 2 * jerk_method.SEED_INTERVALS
    for (size, start, _), (below, _, _) in zip(calls[1:], calls[:-1]):
        assert start == below and size > 1.8 * below
    error = extrapolated_errors((calls[-3][2], calls[-2][2], calls[-1][2]))[1]
    assert answer.duration == calls[-2][2]
    assert answer.optimality_gap == pytest.approx(error / (calls[-2][2] - error), rel=1e-12)
