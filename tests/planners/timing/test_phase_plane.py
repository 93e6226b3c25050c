"""The phase-plane integrator against closed forms, an independent quadrature and TOPP-RA."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from toptraj import robots
from toptraj.planners import METHODS, BoundaryStates, LimitRequest, WaypointPath, build_problem, plan
from toptraj.planners.checks.limit_check import check_limits
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.paths import SplinePath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing import PhasePlaneMethod, ToppraMethod

UR5 = robots.load("ur5")
START = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])


def path_of(spec: WaypointPath) -> SplinePath:
    return SplinePath(spec.waypoints)


def _single_joint(length, robot=UR5, start=START, joint=0):
    goal = start.copy()
    goal[joint] += length
    return WaypointPath(np.array([start, goal]))


@pytest.mark.parametrize("length", [0.3, 1.0, 2.5])
def test_acceleration_only(length):
    """T = 2 sqrt(L / a): the grid holds the single switching point exactly in the middle."""
    accel = UR5.limits.acceleration[0]
    result = plan(build_problem(UR5, _single_joint(length), METHODS["phase_plane"], limits=LimitRequest(kinds=("acceleration",))))
    assert result.duration == pytest.approx(2 * np.sqrt(length / accel), rel=1e-9)


@pytest.mark.parametrize("length", [1.0, 3.0])
def test_velocity_and_acceleration_long_move(length):
    """T = L / v + v / a when L > v^2 / a."""
    v, a = 0.5, 4.0
    timing = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [v] * 6, "acceleration": [a] * 6}))
    result = plan(build_problem(UR5, _single_joint(length), **timing))
    exact = length / v + v / a
    assert result.duration >= exact * (1 - 1e-12)
    assert result.duration == pytest.approx(exact, rel=2e-4)


def test_rigid_horizontal_arm_closed_form():
    """Geering arm turning at the shoulder with the elbow held straight: u1 = M11(0) phi'' and
    u2 = M21(0) phi'' (no velocity terms at psi = 0), so phi'' <= min(25 / M11, 9 / M21) and
    T = 2 sqrt(L / phi''_max)."""
    arm = robots.load("geering_2r")
    m11, m21 = 4.96 + 0.815 + 2 * 1.35, 0.815 + 1.35
    accel = min(25.0 / m11, 9.0 / m21)
    result = plan(build_problem(arm, WaypointPath(np.array([[0.0, 0.0], [1.2, 0.0]])), METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",))))
    assert result.duration == pytest.approx(2 * np.sqrt(1.2 / accel), rel=1e-9)


def _pendulum_time_by_quadrature(theta_goal, I=4.167e-3, m=1.0, l=0.1, g=9.81):
    """Yamamoto arm swinging joint 1 from 0 to theta_goal with joint 2 held at 0, timed
    independently of toptraj: along theta2 = 0 eq. (31) reduces to
        u1 = (2 I + 10 m l^2) th'' - 4 m g l sin th,  u2 = (I + 3 m l^2) th'' - m g l sin th,
    so the path acceleration bounds depend on th only. Maximum acceleration from rest meets
    maximum deceleration to rest at th*, and T = int dth / sqrt(x(th)) by adaptive quadrature."""
    m11, m21 = 2 * I + 10 * m * l**2, I + 3 * m * l**2

    def most(th):
        gravity = m * g * l * np.sin(th)
        return min((10 + 4 * gravity) / m11, (5 + gravity) / m21)

    def least(th):
        gravity = m * g * l * np.sin(th)
        return max((-10 + 4 * gravity) / m11, (-5 + gravity) / m21)

    def x_forward(th):
        return 2 * quad(most, 0.0, th, epsabs=1e-13, epsrel=1e-13)[0]

    def x_backward(th):
        return 2 * quad(lambda t: -least(t), th, theta_goal, epsabs=1e-13, epsrel=1e-13)[0]

    meet = brentq(lambda th: x_forward(th) - x_backward(th), 1e-9, theta_goal - 1e-9, xtol=1e-14)
    first = quad(lambda th: 1 / np.sqrt(x_forward(th)), 0.0, meet, epsabs=1e-11, epsrel=1e-11, limit=200)[0]
    second = quad(lambda th: 1 / np.sqrt(x_backward(th)), meet, theta_goal, epsabs=1e-11, epsrel=1e-11, limit=200)[0]
    return first + second


@pytest.mark.parametrize("theta_goal", [0.5, 1.5])
def test_torque_limited_pendulum_against_quadrature(theta_goal):
    arm = robots.load("yamamoto_2r")
    exact = _pendulum_time_by_quadrature(theta_goal)
    path = WaypointPath(np.array([[0.0, 0.0], [theta_goal, 0.0]]))
    result = plan(build_problem(arm, path, METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",))))
    assert exact <= result.duration <= exact * (1 + 1e-3)  # the 0.1 % standard of DESIGN.md
    constraints = build_path_constraints(path_of(path), arm, arm.limits, ("torque",), path_grid(path_of(path)))
    tight = PhasePlaneMethod(tolerance=2e-5, max_refinements=8).solve(constraints)
    assert exact <= tight.duration <= exact * (1 + 3e-5)


def test_duration_converges_from_above_as_the_grid_is_refined():
    path = SplinePath(np.array([[0, -1.2, 1.0, 0, 0, 0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]]))
    unrefined = PhasePlaneMethod(max_refinements=0)
    durations = []
    for n in (50, 100, 200, 400, 800, 1600):
        constraints = build_path_constraints(path, UR5, UR5.limits, ("velocity", "acceleration", "torque"), path_grid(path, n))
        durations.append(unrefined.solve(constraints).duration)
    steps = -np.diff(durations)
    assert np.all(steps > 0)  # every refinement shortens the (conservative) answer
    assert np.all(steps[1:] < 0.7 * steps[:-1])  # and by less each time: it converges


def _random_spline(robot, rng, n_waypoints):
    lower = np.maximum(robot.limits.position_lower, -3.0)
    upper = np.minimum(robot.limits.position_upper, 3.0)
    margin = 0.15 * (upper - lower)
    while True:
        waypoints = rng.uniform(lower + margin, upper - margin, (n_waypoints, robot.dof))
        path = SplinePath(waypoints)
        q = path(np.linspace(0, 1, 500))
        if np.all(q >= lower) and np.all(q <= upper):
            return path


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_agrees_with_fine_toppra_on_random_paths(name):
    """50 seeded random spline paths: within 0.1 % of TOPP-RA on a 3000-interval grid, limits
    held on a dense resampling, and, refining for the duration alone (TOPP-RA holds the limits
    at the grid points only), never longer than TOPP-RA on the default grid."""
    robot = robots.load(name)
    rng = np.random.default_rng(1234 if name == "ur5" else 4321)
    kinds = ("velocity", "acceleration", "torque")
    phase_plane, toppra = PhasePlaneMethod(), ToppraMethod()
    duration_only = PhasePlaneMethod(excursion=None)
    worst = 0.0
    for _ in range(50):
        path = _random_spline(robot, rng, int(rng.integers(2, 6)))
        default = build_path_constraints(path, robot, robot.limits, kinds, path_grid(path))
        ours = phase_plane.solve(default)
        reference = toppra.solve(build_path_constraints(path, robot, robot.limits, kinds, path_grid(path, 3000)))
        baseline = toppra.solve(default)
        gap = abs(ours.duration / reference.duration - 1)
        worst = max(worst, gap)
        assert gap <= 1e-3
        assert duration_only.solve(default).duration <= baseline.duration * (1 + 1e-9)
        utilization = check_limits(path, ours, robot, robot.limits).utilization
        assert max(value.max() for value in utilization.values()) <= 1.005
    assert worst < 1e-3


@pytest.mark.parametrize(
    "name, waypoints",
    [("geering_2r", [[0.0, 0.0], [0.76, 0.0]]), ("yamamoto_2r", np.radians([[45.0, -90.0], [-90.0, 0.0]]))],
)
def test_paper_arm_straight_lines_agree_with_fine_toppra(name, waypoints):
    robot = robots.load(name)
    path = SplinePath(np.array(waypoints, dtype=float))
    ours = PhasePlaneMethod().solve(build_path_constraints(path, robot, robot.limits, ("torque",), path_grid(path)))
    reference = ToppraMethod().solve(build_path_constraints(path, robot, robot.limits, ("torque",), path_grid(path, 5000)))
    assert ours.duration == pytest.approx(reference.duration, rel=1e-3)


def test_nonzero_boundary_speeds_and_the_limit_above_the_mvc():
    path = _single_joint(2.0)
    tangent = np.zeros(6)
    tangent[0] = 1.0
    timing = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [1.0] * 6, "acceleration": [4.0] * 6}), boundary=BoundaryStates(start_velocity=0.5 * tangent, end_velocity=0.25 * tangent))
    result = plan(build_problem(UR5, path, **timing))
    assert result.samples.qd[0] == pytest.approx(0.5 * tangent, abs=1e-9)
    assert result.samples.qd[-1] == pytest.approx(0.25 * tangent, abs=1e-9)
    # Closed form: accelerate 0.5 -> 1, cruise, decelerate 1 -> 0.25 at 4 rad/s^2.
    accelerate, decelerate = (1 - 0.5**2) / (2 * 4), (1 - 0.25**2) / (2 * 4)  # distances
    exact = (1 - 0.5) / 4 + (1 - 0.25) / 4 + (2.0 - accelerate - decelerate) / 1.0
    assert result.duration == pytest.approx(exact, rel=2e-4)
    too_fast = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [1.0] * 6, "acceleration": [4.0] * 6}), boundary=BoundaryStates(start_velocity=1.5 * tangent))
    with pytest.raises(InfeasiblePath, match="start path speed"):
        plan(build_problem(UR5, path, **too_fast))


def test_switching_points_are_reported_with_their_kind():
    path = WaypointPath(np.array([[0, -1.2, 1.0, 0, 0, 0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]]))
    result = plan(build_problem(UR5, path, METHODS["phase_plane"]))
    kinds = {kind for _, kind in result.phase_plane.switch_points}
    assert "deceleration" in kinds
    assert kinds & {"tangent", "singular", "discontinuity"}
    assert all(0.0 < s < 1.0 for s, _ in result.phase_plane.switch_points)
