"""min_cost: the minimum of the integral of (1 + beta |tau|^2) dt along a path (Yamamoto's MCTP)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.timing.min_cost import MinCostMethod

YAMAMOTO_LINE = np.radians([[45.0, -90.0], [-90.0, 0.0]])
BETA = 0.03


def _yamamoto_torques(theta, dtheta, ddtheta, I=4.167e-3, m=1.0, l=0.1, g=9.81):
    """Eq. (31) of the paper, vectorized over rows (n, 2)."""
    t1, t2 = theta[:, 0], theta[:, 1]
    d1, d2 = dtheta[:, 0], dtheta[:, 1]
    a1, a2 = ddtheta[:, 0], ddtheta[:, 1]
    u1 = ((2 * I + 2 * m * l**2 * (3 + 2 * np.cos(t2))) * a1 + (I + m * l**2 * (1 + 2 * np.cos(t2))) * a2
          - 2 * m * l**2 * np.sin(t2) * (2 * d1 * d2 + d2**2) - m * g * l * (3 * np.sin(t1) + np.sin(t1 + t2)))
    u2 = ((I + m * l**2 * (1 + 2 * np.cos(t2))) * a1 + (I + m * l**2) * a2 + 2 * m * l**2 * np.sin(t2) * d1**2
          - m * g * l * np.sin(t1 + t2))
    return np.column_stack([u1, u2])


def _cost_by_time_collocation(beta, nodes=60):
    """The same problem solved another way: trapezoidal collocation in time along the straight
    joint line, with the paper's own equations of motion and scipy's SLSQP. Variables: the
    duration T and s, sd, sdd at ``nodes`` + 1 instants."""
    start, delta = YAMAMOTO_LINE[0], YAMAMOTO_LINE[1] - YAMAMOTO_LINE[0]
    K = nodes

    def unpack(z):
        return z[0], z[1 : K + 2], z[K + 2 : 2 * K + 3], z[2 * K + 3 :]

    def torques(z):
        T, s, v, u = unpack(z)
        return _yamamoto_torques(start + np.outer(s, delta), np.outer(v, delta), np.outer(u, delta))

    def cost(z):
        T, s, v, u = unpack(z)
        f = 1 + beta * np.sum(torques(z) ** 2, axis=1)
        return T / K * (0.5 * f[0] + f[1:-1].sum() + 0.5 * f[-1])

    def defects(z):
        T, s, v, u = unpack(z)
        h = T / K
        return np.concatenate([
            s[1:] - s[:-1] - h / 2 * (v[1:] + v[:-1]),
            v[1:] - v[:-1] - h / 2 * (u[1:] + u[:-1]),
            [s[0], s[-1] - 1.0, v[0], v[-1]],
        ])

    def torque_margin(z):
        tau = torques(z)
        return np.concatenate([10 - np.abs(tau[:, 0]), 5 - np.abs(tau[:, 1])])

    T0 = 0.5
    tau = np.linspace(0, 1, K + 1)
    guess = np.concatenate([[T0], 3 * tau**2 - 2 * tau**3, (6 * tau - 6 * tau**2) / T0, (6 - 12 * tau) / T0**2])
    result = minimize(cost, guess, method="SLSQP", constraints=[{"type": "eq", "fun": defects}, {"type": "ineq", "fun": torque_margin}],
                      bounds=[(0.05, 5.0)] + [(None, None)] * (3 * K + 3), options={"maxiter": 500, "ftol": 1e-12})
    assert result.success, result.message
    return result.fun


def test_yamamoto_straight_line_cost():
    """Table 2's J = 0.95859 on the straight joint line is an upper bound (the paper's few
    B-spline control points for lambda(s)); the convex program finds the global optimum of the
    same discretized problem, and a time-domain collocation with the paper's equations agrees."""
    arm = robots.load("yamamoto_2r")
    path = WaypointPath(YAMAMOTO_LINE)
    result = plan(build_problem(arm, path, MinCostMethod(BETA), limits=LimitRequest(kinds=("torque",)), grid=600))
    assert result.cost <= 0.95859
    independent = _cost_by_time_collocation(BETA)
    assert result.cost == pytest.approx(independent, rel=2e-3)
    assert result.peak_utilization["torque"].max() <= 1.005
    # The cost integral, recomputed from the returned samples by the trapezoidal rule.
    samples = plan(build_problem(arm, path, MinCostMethod(BETA), limits=LimitRequest(kinds=("torque",)), grid=600, sampling=Sampling(dt=0.0005))).samples
    integrand = 1 + BETA * np.sum(samples.tau**2, axis=1)
    assert np.trapezoid(integrand, samples.t) == pytest.approx(result.cost, rel=2e-3)


@pytest.mark.parametrize("name, waypoints", [("yamamoto_2r", YAMAMOTO_LINE), ("ur5", [[0, -1.2, 1.0, 0, 0.3, 0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]])])
def test_beta_zero_is_time_optimal(name, waypoints):
    """With beta = 0 the cost is the duration, and the convex program, the phase-plane
    integrator and TOPP-RA agree within 0.5 % (three independent computations)."""
    robot = robots.load(name)
    path = WaypointPath(np.array(waypoints, dtype=float))
    durations = {
        method: plan(build_problem(robot, path, METHODS[method], limits=LimitRequest(kinds=("velocity", "acceleration", "torque")))).duration
        for method in ("min_cost", "phase_plane", "toppra")
    }
    assert durations["min_cost"] == pytest.approx(durations["phase_plane"], rel=5e-3)
    assert durations["min_cost"] == pytest.approx(durations["toppra"], rel=5e-3)


def test_energy_weight_slows_the_motion_and_lowers_torque():
    arm = robots.load("yamamoto_2r")
    path = WaypointPath(YAMAMOTO_LINE)
    fast = plan(build_problem(arm, path, METHODS["min_cost"], limits=LimitRequest(kinds=("torque",))))
    gentle = plan(build_problem(arm, path, MinCostMethod(BETA), limits=LimitRequest(kinds=("torque",))))
    assert gentle.duration > fast.duration
    assert gentle.peak_utilization["torque"].max() < fast.peak_utilization["torque"].max()
    assert gentle.cost < fast.duration * (1 + BETA * 0) + BETA * np.trapezoid(np.sum(fast.samples.tau**2, axis=1), fast.samples.t)


def test_a_weighted_cost_on_a_fine_grid_is_solved_and_agrees_with_a_coarser_one():
    """ur5 through four waypoints, beta = 0.01 (N m)^-2: Clarabel failed on 1,500 intervals while
    the torques entered its cones in N m (tau^2 of thousands); in units of each joint's limit it
    solves, and the cost agrees with the 1,000-interval one within the discretization's 1e-4."""
    arm = robots.load("ur5")
    path = WaypointPath(np.array([[0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
                                  [1.5, -0.5, 0.8, -1.0, 1.0, 0.8], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]]))
    costs = [plan(build_problem(arm, path, MinCostMethod(0.01), grid=grid)).cost for grid in (1000, 1500)]
    assert costs[1] == pytest.approx(costs[0], rel=1e-4)


def test_the_cost_reported_with_viscous_friction_is_that_of_the_motion_s_own_torques():
    """z1's URDF has viscous friction (1-2 N m s): the cost's torques left it out, and the cost
    reported (2.07) was 16 % below the integral of (1 + beta |tau|^2) over the answer's own
    torques (2.47; ``tau`` includes the friction). The cost now counts it, within 0.2 % of that
    integral over samples every 0.5 ms (the difference: the grid's midpoint rule)."""
    from toptraj.service.planning import plan_request
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    body = {
        "robot": "z1",
        "path": {"waypoints": [[-0.698868, 0.477821, -2.377876, 1.411984, 0.092658, -2.615465],
                               [-2.250958, 0.453298, -0.390371, -1.518004, 0.956566, 0.887468]]},
        "timing": {"method": "min_cost", "cost": {"torque_weight": 0.01}},
        "output": {"dt": 0.0005},
    }
    answer = plan_request(TrajectoryRequest.model_validate(body))
    integral = np.trapezoid(1.0 + 0.01 * (answer.samples.tau**2).sum(axis=1), answer.samples.t)
    assert answer.cost == pytest.approx(integral, rel=2e-3)


def test_a_solver_failure_is_told_in_the_request_s_terms(monkeypatch):
    """Clarabel failing (on a spline through waypoints 6e-7 rad apart) was answered with cvxpy's
    advice to its caller: "Try another solver, or solve with verbose=True"."""
    import cvxpy as cp

    from toptraj.planners.errors import TimingFailed

    def fails(self, *args, **kwargs):
        raise cp.error.SolverError("Solver 'CLARABEL' failed. Try another solver, or solve with verbose=True for more information.")

    monkeypatch.setattr(cp.Problem, "solve", fails)
    arm = robots.load("yamamoto_2r")
    problem = build_problem(arm, WaypointPath(YAMAMOTO_LINE), MinCostMethod(BETA), limits=LimitRequest(kinds=("torque",)), sampling=Sampling(dt=0.01))
    with pytest.raises(TimingFailed) as failed:
        plan(problem)
    assert "verbose" not in failed.value.detail and "another solver" not in failed.value.detail
    assert "phase_plane or toppra time the path" in failed.value.detail
