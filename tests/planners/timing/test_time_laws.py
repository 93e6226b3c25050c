"""Classical time laws: the lecture's worked numbers, Angeles 6.1, and the shortest durations."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, BoundaryStates, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath, InvalidRequest
from toptraj.planners.generators.joint_moves import ViaPoints
from toptraj.planners.timing.laws.method import ClassicalMethod
from toptraj.planners.timing.laws.profiles import (
    PROFILES,
    CubicProfile,
    CycloidalProfile,
    QuinticProfile,
    TrapezoidalProfile,
    cubic_coefficients,
    polynomial_derivatives,
    quintic_coefficients,
)
from toptraj.service.problems import detail, status_of


def test_lecture_example_1_cubic():
    """30 deg to 75 deg in 5 s, at rest at both ends: theta = 30 + 5.4 t^2 - 0.72 t^3."""
    coefficients = cubic_coefficients(30.0, 0.0, 75.0, 0.0, 5.0)
    assert coefficients == pytest.approx([30.0, 0.0, 5.4, -0.72], abs=1e-12)
    theta = polynomial_derivatives(coefficients, np.array([1.0, 2.0, 3.0, 4.0]), 1)[0]
    assert theta == pytest.approx([34.68, 45.84, 59.16, 70.32], abs=1e-9)
    # Peak acceleration at the ends: 6 (75 - 30) / 5^2 = 10.8 deg/s^2 (the lecture's formula).
    acceleration = polynomial_derivatives(coefficients, np.array([0.0, 5.0]), 3)[2]
    assert acceleration == pytest.approx([10.8, -10.8], abs=1e-12)


def test_lecture_example_2_quintic():
    """Same move with 5 deg/s^2 at the start and -5 deg/s^2 at the end."""
    coefficients = quintic_coefficients(30.0, 0.0, 5.0, 75.0, 0.0, -5.0, 5.0)
    assert coefficients == pytest.approx([30.0, 0.0, 2.5, 1.6, -0.58, 0.0464], abs=1e-12)


def test_angeles_6_1_trapezoidal_peak_speed():
    """s'_max = 2 / (1 - tau1 + tau2), and s rises from 0 to 1 (problem 6.1 (a), (b))."""
    for tau1, tau2 in [(0.2, 0.9), (1 / 3, 2 / 3), (0.1, 0.5), (0.4, 0.4)]:
        profile = TrapezoidalProfile(tau1, tau2)
        tau = np.linspace(0, 1, 20001)
        sigma, speed, acceleration, _ = profile.derivatives(tau)
        assert speed.max() == pytest.approx(2 / (1 - tau1 + tau2), rel=1e-12)
        assert sigma[0] == 0.0 and sigma[-1] == pytest.approx(1.0, abs=1e-12)
        # Problem 6.1 (b), piecewise s(tau), checked on each piece.
        denominator = 1 - tau1 + tau2
        first = tau <= tau1
        assert sigma[first] == pytest.approx(tau[first] ** 2 / (tau1 * denominator), abs=1e-12)
        middle = (tau >= tau1) & (tau <= tau2)
        assert sigma[middle] == pytest.approx((2 * tau[middle] - tau1) / denominator, abs=1e-12)
        last = tau >= tau2
        expected = (tau[last] ** 2 + tau2**2 - 2 * tau[last] - tau1 * (tau2 - 1)) / ((tau2 - 1) * denominator)
        assert sigma[last] == pytest.approx(expected, abs=1e-12)


def test_cycloidal_peak_acceleration_is_two_pi():
    tau = np.linspace(0, 1, 100001)
    sigma, speed, acceleration, _ = CycloidalProfile().derivatives(tau)
    assert np.abs(acceleration).max() == pytest.approx(2 * np.pi, rel=1e-9)
    assert speed[[0, -1]] == pytest.approx([0, 0]) and acceleration[[0, -1]] == pytest.approx([0, 0], abs=1e-12)


@pytest.mark.parametrize("profile", [CubicProfile(), QuinticProfile(), TrapezoidalProfile(0.2, 0.9), CycloidalProfile()])
def test_profiles_are_consistent(profile):
    """sigma(0) = 0, sigma(1) = 1, at rest at both ends, derivatives match finite differences."""
    tau = np.linspace(0.01, 0.99, 97)
    sigma, d1, d2, d3 = profile.derivatives(tau)
    h = 1e-6
    assert d1 == pytest.approx((profile.derivatives(tau + h)[0] - profile.derivatives(tau - h)[0]) / (2 * h), abs=1e-6)
    assert profile.derivatives(np.array([0.0, 1.0]))[0] == pytest.approx([0.0, 1.0], abs=1e-12)
    assert profile.derivatives(np.array([0.0, 1.0]))[1] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert profile.tau_at(sigma) == pytest.approx(tau, abs=1e-10)


UR5 = robots.load("ur5")
LAWS = ["cubic", "quintic", "trapezoidal", "cycloidal"]


@pytest.mark.parametrize("interpolation", ["spline", "linear"])
@pytest.mark.parametrize("law", LAWS)
def test_shortest_law_respects_every_limit_and_is_not_faster_than_optimal(law, interpolation):
    # The cubic and the trapezoid have acceleration steps: no jerk limit for them (see below).
    smooth = law in ("quintic", "cycloidal")
    kinds = ("velocity", "acceleration", "torque", "jerk")[: 4 if smooth else 3]
    path = WaypointPath(np.array(UR5_WAYPOINTS), interpolation)
    result = plan(build_problem(UR5, path, METHODS[law], limits=LimitRequest(kinds=kinds), sampling=Sampling(dt=0.001)))
    optimal = plan(build_problem(UR5, path, METHODS["phase_plane"], limits=LimitRequest(kinds=kinds[:3])))
    assert result.duration >= optimal.duration
    for kind in kinds:
        assert result.peak_utilization[kind].max() <= 1.005, kind
    if smooth:  # the jerk of the 1 ms samples, independently of the reported one
        samples = result.samples
        jerk = np.diff(samples.qdd, axis=0) / np.diff(samples.t)[:, None]
        assert np.abs(jerk / UR5.limits.jerk).max() <= 1.005
    # The binding limit is really reached: the law is as short as it can be.
    binding = result.binding
    joint = UR5.joint_names.index(binding.joint)
    assert 0.995 <= result.peak_utilization[binding.kind][joint] <= 1.005
    assert result.samples.qd[0] == pytest.approx(np.zeros(6), abs=1e-12)
    assert result.samples.q[-1] == pytest.approx(UR5_WAYPOINTS[-1], abs=1e-9)


CUBIC_STEPS = [0.0, 1.0]
TRAPEZOID_STEPS = [0.0, 1 / 3, 2 / 3, 1.0]


@pytest.mark.parametrize(
    "law, steps, interpolation",
    [
        ("cubic", CUBIC_STEPS, "spline"),
        ("cubic", CUBIC_STEPS, "linear"),
        ("cubic", CUBIC_STEPS, "via"),
        ("trapezoidal", TRAPEZOID_STEPS, "spline"),
        ("trapezoidal", TRAPEZOID_STEPS, "linear"),
    ],
)
def test_laws_with_acceleration_steps_refuse_a_jerk_limit(law, steps, interpolation):
    """The cubic leaves rest with sigma''(0) = 6 and the trapezoid switches between constant
    accelerations: an infinite jerk at each step, whatever the duration (on 1 ms samples of
    the unchecked law the jerk reaches 30 to 100 times ur5's limit). Via points take cubic or
    quintic segments only: the trapezoid there is refused before any limit (next test)."""
    path = WaypointPath(np.array(UR5_WAYPOINTS), interpolation)
    method = ViaPoints(METHODS[law]) if interpolation == "via" else METHODS[law]
    with pytest.raises(InfeasiblePath) as refused:
        plan(build_problem(UR5, path, method, limits=LimitRequest(kinds=("velocity", "acceleration", "jerk"))))
    assert (refused.value.limit, refused.value.rule) == ("jerk", "law_acceleration_steps")
    assert refused.value.steps == pytest.approx(ClassicalMethod(PROFILES[law]()).profile.acceleration_steps())
    assert "quintic" in detail(refused.value)
    assert ClassicalMethod(PROFILES[law]()).profile.acceleration_steps() == pytest.approx(steps)


@pytest.mark.parametrize("kinds", [("velocity", "acceleration"), ("velocity", "acceleration", "jerk")])
def test_via_points_refuse_the_trapezoid_whatever_the_limits(kinds):
    """Via points are passed by per-joint cubic or quintic segments in time: the trapezoid
    is refused (422) naming the methods that take them, with or without a jerk limit."""
    path = WaypointPath(np.array(UR5_WAYPOINTS), "via")
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(UR5, path, ViaPoints(METHODS["trapezoidal"]), limits=LimitRequest(kinds=kinds)))
    assert status_of(refused.value) == 422
    assert (refused.value.field, refused.value.value, refused.value.alternatives) == ("method", "trapezoidal", ("cubic", "quintic"))
    assert "'cubic' or 'quintic'" in detail(refused.value) and "trapezoidal" in detail(refused.value)


def test_single_joint_closed_forms():
    """One joint, acceleration limit a, distance L: the cubic needs T = sqrt(6 L / a), the
    cycloidal T = sqrt(2 pi L / a), the trapezoid T = sqrt(L s'_max / (a tau1))."""
    start = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])
    goal = start + np.array([1.2, 0, 0, 0, 0, 0])
    path = WaypointPath(np.array([start, goal]))
    a = UR5.limits.acceleration[0]
    expected = {
        "cubic": np.sqrt(6 * 1.2 / a),
        "cycloidal": np.sqrt(2 * np.pi * 1.2 / a),
        "trapezoidal": np.sqrt(1.2 * 1.5 / (a / 3)),
        "quintic": np.sqrt(10 / np.sqrt(3) * 1.2 / a),
    }
    for law, duration in expected.items():
        result = plan(build_problem(UR5, path, METHODS[law], limits=LimitRequest(kinds=("acceleration",))))
        assert result.duration == pytest.approx(duration, rel=1e-6), law
        assert result.binding.kind == "acceleration" and result.binding.joint == "shoulder_pan_joint"


def test_given_duration_and_boundary_states():
    start = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])
    goal = start + np.array([1.0, 0, 0, 0, 0, 0])
    path = WaypointPath(np.array([start, goal]))
    slow = plan(build_problem(UR5, path, METHODS["quintic"], duration=5.0))
    assert slow.duration == pytest.approx(5.0, abs=1e-12)
    assert slow.binding is None
    # The lecture's example 2 as a joint move: 5 deg/s^2 in, -5 deg/s^2 out, 45 deg in 5 s.
    goal = start + np.radians([45.0, 0, 0, 0, 0, 0])
    direction = np.array([1.0, 0, 0, 0, 0, 0])
    timing = dict(method=METHODS["quintic"], boundary=BoundaryStates(start_acceleration=np.radians(5.0) * direction, end_acceleration=np.radians(-5.0) * direction), duration=5.0)
    result = plan(build_problem(UR5, WaypointPath(np.array([start, goal])), **timing, sampling=Sampling(dt=1.0)))
    theta = np.degrees(result.samples.q[:, 0] - start[0]) + 30.0
    expected = polynomial_derivatives(np.array([30.0, 0.0, 2.5, 1.6, -0.58, 0.0464]), np.arange(6.0), 1)[0]
    assert theta == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("law", ["cubic", "quintic"])
def test_shortest_law_with_boundary_velocity(law):
    """A law that starts moving: the boundary velocity is honoured and the shortest duration
    keeps every limit, with one limit binding."""
    start = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])
    goal = start + np.array([1.0, 0.5, 0, 0, 0, 0])
    direction = (goal - start) / np.linalg.norm(goal - start)
    timing = dict(method=METHODS[law], limits=LimitRequest(kinds=("velocity", "acceleration")), boundary=BoundaryStates(start_velocity=0.5 * direction))
    result = plan(build_problem(UR5, WaypointPath(np.array([start, goal])), **timing))
    assert result.samples.qd[0] == pytest.approx(0.5 * direction, abs=1e-9)
    assert result.samples.qd[-1] == pytest.approx(np.zeros(6), abs=1e-9)
    top = max(result.peak_utilization[kind].max() for kind in ("velocity", "acceleration"))
    assert 0.99 <= top <= 1.005


#: A recorded ur10 path that nearly stands still twice (waypoints 5e-6 rad apart): its spline bends
#: sharply over stretches of s far shorter than the law's uniform samples in time see.
NEAR_REPEATS = [
    [-1.773806, -1.804332, 2.443502, -2.525893, 0.155449, 2.253263],
    [-1.773808, -1.804337, 2.443507, -2.525893, 0.155451, 2.253256],
    [-1.773764, -1.80428, 2.443897, -2.526192, 0.155007, 2.252595],
    [-1.773764, -1.804281, 2.443898, -2.526192, 0.155008, 2.252595],
    [-0.699164, -0.232357, 0.027847, 0.407466, -1.45997, 2.010171],
    [-0.699181, -0.232358, 0.027819, 0.407438, -1.459986, 2.010222],
]


def test_a_law_on_a_spline_through_nearly_repeated_waypoints_is_checked_where_the_spline_bends():
    """The cubic law's limit check sampled 1,000 instants per stretch: it reported an acceleration
    peak of 0.753 and a gap of 15 % where the motion reached 1.005 times the limit, and a
    duration too short for the law was refused with "use more grid points", which no grid
    helped. It now passes the constraints' grid points too: the answer's peak is the motion's
    (2,000,001 instants of the law on SciPy's natural spline through the waypoints, chord-length
    knots, computed here), reached, and a short duration is told the shortest."""
    from scipy.interpolate import CubicSpline

    arm = robots.load("ur10")
    waypoints = np.array(NEAR_REPEATS)
    limits = LimitRequest(kinds=("velocity", "acceleration"), scales={"velocity": 0.838})
    path = WaypointPath(waypoints, min_spacing=0.0)  # the spline through every waypoint, as recorded
    result = plan(build_problem(arm, path, METHODS["cubic"], limits=limits, sampling=Sampling(dt=0.01)))
    knots = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))))
    spline = CubicSpline(knots / knots[-1], waypoints, bc_type="natural")
    T = result.duration
    tau = np.linspace(0.0, 1.0, 2_000_001)
    s, sd, sdd = 3 * tau**2 - 2 * tau**3, (6 * tau - 6 * tau**2) / T, (6 - 12 * tau) / T**2
    acceleration = spline(s, 1) * sdd[:, None] + spline(s, 2) * (sd**2)[:, None]
    peaks = np.abs(acceleration).max(axis=0) / arm.limits.acceleration
    assert peaks.max() == pytest.approx(1.0, abs=1e-3)
    assert result.peak_utilization["acceleration"] == pytest.approx(peaks, abs=1e-3)
    assert result.accuracy.relative_gap < 1e-3
    with pytest.raises(InfeasiblePath) as refused:
        plan(build_problem(arm, path, METHODS["cubic"], limits=limits, duration=0.9 * T))
    assert detail(refused.value).startswith(f"timing.duration {0.9 * T:g} s is too short for the cubic law")
