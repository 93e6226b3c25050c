"""Angeles, solutions to problems 6.1 (c), 6.2 and 6.3: periodic cubic splines of the trapezoidal
program, the displacement program recovered from its sampled accelerations, and the trapezoid
with cycloidal blends; and the time laws built on them, asked for over HTTP."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, BoundaryStates, LimitRequest, TimeLaw, WaypointPath, build_problem, plan
from toptraj.planners.errors import InfeasiblePath, InvalidRequest
from toptraj.planners.generators.joint_moves import ViaPoints
from toptraj.planners.timing.laws.profiles import CycloidalBlendProfile, CycloidalProfile, QuinticProfile, TrapezoidalProfile
from toptraj.planners.timing.laws.splines import SplineProfile, clamped_spline, periodic_spline, spline_from_accelerations
from toptraj.service.problems import detail

TAU1, TAU2 = 0.2, 0.9
TRAPEZOID = TrapezoidalProfile(TAU1, TAU2)
FINE = np.linspace(0.0, 1.0, 200_001)


def assert_close(actual, expected, tol):
    """Largest |actual - expected| within ``tol`` (fast on long arrays)."""
    assert np.max(np.abs(np.asarray(actual) - np.asarray(expected))) <= tol


def periodic_part(tau):
    """s_p(tau) = s(tau) - tau of the trapezoidal program (problem 6.1 (b))."""
    return TRAPEZOID.derivatives(tau)[0] - tau


@pytest.mark.parametrize("n_points, peak, trough", [(8, 8.901004, -5.018651), (10, 9.856978, -6.260669)])
def test_6_1_c_periodic_spline_peak_acceleration(n_points, peak, trough):
    """Problem 6.1 (c): the periodic cubic spline through N equally spaced points of s_p (eq. 80).

    Its acceleration is piecewise linear, so its peak lies on a supporting point: 8.901 at
    tau = 1/7 for N = 8 (the text reads "about eight" off its Fig. 19 (b)) and 9.857 at tau = 1/9
    for N = 10 (the text's Matlab listing sets N = 10). The trapezoid's own levels are
    s'_max / tau1 = 2 / (tau1 (1 - tau1 + tau2)) = 5.882 ("about six") while accelerating and
    -s'_max / (1 - tau2) = -11.765 while decelerating, which the text leaves out: eight points
    miss the short deceleration (the spline only reaches -5.02; problem 6.2 notes the same). The
    cycloid's peak is 2 pi = 6.283 ("slightly over six")."""
    points = np.linspace(0.0, 1.0, n_points)
    values = periodic_part(points)
    values[-1] = values[0] = 0.0
    spline = periodic_spline(values)
    # Independent: scipy's periodic spline through the same points.
    reference = CubicSpline(points, values, bc_type="periodic")
    assert spline.second == pytest.approx(reference(points, 2), abs=1e-9)
    assert_close(spline.derivatives(FINE)[0], reference(FINE), 1e-12)
    acceleration = spline.derivatives(np.union1d(FINE, points))[2]
    assert acceleration.max() == pytest.approx(peak, abs=1e-6)
    assert acceleration.min() == pytest.approx(trough, abs=1e-6)
    assert abs(acceleration.max() - 8.0) < 2.0  # "about eight"
    levels = TRAPEZOID.derivatives(np.array([0.1, 0.95]))[2]
    assert levels == pytest.approx([2 / (TAU1 * 1.7), -2 / (0.1 * 1.7)], rel=1e-12)
    assert levels[0] == pytest.approx(6.0, abs=0.2)  # "about six"
    assert np.abs(CycloidalProfile().derivatives(FINE)[2]).max() == pytest.approx(2 * np.pi, rel=1e-9)


def test_6_1_c_periodic_spline_does_not_start_at_rest():
    """Why the served spline law is clamped: s = tau + s_p with the periodic spline of s_p moves
    at 1 + s_p'(0) = 0.447 (N = 8) at both ends, not at rest (a cycle's speed, not a stop)."""
    points = np.linspace(0.0, 1.0, 8)
    values = periodic_part(points)
    values[-1] = values[0] = 0.0
    spline = periodic_spline(values)
    speed = 1.0 + spline.derivatives(np.array([0.0, 1.0]))[1]
    assert speed == pytest.approx([0.447223, 0.447223], abs=1e-6)


def test_6_2_displacement_from_sampled_accelerations():
    """Problem 6.2: the acceleration program sampled at 25 equally spaced points (s'' = 0 at
    both ends, as the text sets for periodicity), the displacement from eq. (83) with
    s(0) = s(1) = 0, compared with s_p(tau): the largest error is 0.01296 (at tau = 0.196, where
    the acceleration jumps between two samples), 15 % of the largest |s_p| = tau1 (1 - tau1 +
    tau2) / 4 = 0.085, 1.3 % of the unit displacement ("a good approximation" in the text, which
    gives no figure); at the supporting points themselves it is 0.0128 (the samples do not see
    where between two points the acceleration jumps)."""
    points = np.linspace(0.0, 1.0, 25)
    accelerations = TRAPEZOID.derivatives(points)[2]
    accelerations[[0, -1]] = 0.0
    spline = spline_from_accelerations(accelerations)
    # Independent: integrate the piecewise-linear acceleration twice, fixing s(0) = s(1) = 0.
    acceleration = np.interp(FINE, points, accelerations)
    step = FINE[1] - FINE[0]
    speed = np.concatenate(([0.0], np.cumsum(0.5 * (acceleration[1:] + acceleration[:-1]) * step)))
    position = np.concatenate(([0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * step)))
    position -= FINE * position[-1]
    recovered = spline.derivatives(FINE)[0]
    assert_close(recovered, position, 1e-9)
    error = np.abs(recovered - periodic_part(FINE))
    assert error.max() == pytest.approx(0.012958, abs=2e-6)
    assert FINE[np.argmax(error)] == pytest.approx(0.196, abs=1e-3)
    assert np.abs(periodic_part(FINE)).max() == pytest.approx(TAU1 * (1 - TAU1 + TAU2) / 4, rel=1e-6)
    # More points, a closer program: the error falls below 0.005 with 100.
    finer = np.linspace(0.0, 1.0, 100)
    more = TRAPEZOID.derivatives(finer)[2]
    more[[0, -1]] = 0.0
    assert np.abs(spline_from_accelerations(more).derivatives(FINE)[0] - periodic_part(FINE)).max() < 0.005


def test_6_3_trapezoid_with_cycloidal_blends():
    """Problem 6.3, eqs. (86), (87): on the rise s = (A/2)[tau/tau1 - sin(pi tau/tau1)/pi] with
    A = tau1 s'_max = 2 tau1 / (1 - tau1 + tau2) (the text stops before A; continuity of s' at
    tau1 and s(1) = 1 fix it, see ``CycloidalBlendProfile``)."""
    profile = CycloidalBlendProfile(TAU1, TAU2)
    sigma, speed, acceleration, jerk = profile.derivatives(FINE)
    v = 2 / (1 - TAU1 + TAU2)
    A = TAU1 * v
    rise = FINE <= TAU1
    assert_close(sigma[rise], A / 2 * (FINE[rise] / TAU1 - np.sin(np.pi * FINE[rise] / TAU1) / np.pi), 1e-14)
    assert_close(speed[rise], A / (2 * TAU1) * (1 - np.cos(np.pi * FINE[rise] / TAU1)), 1e-13)
    assert sigma[[0, -1]] == pytest.approx([0.0, 1.0], abs=1e-14)
    assert speed[[0, -1]] == pytest.approx([0.0, 0.0], abs=1e-14)
    assert speed.max() == pytest.approx(v, rel=1e-12)
    # Continuous speed and acceleration (no jump between neighbouring samples beyond the slope).
    assert np.abs(np.diff(acceleration)).max() < 5e-3  # steepest slope 18.5 pi / 0.1 times the 5e-6 step
    # Peaks pi / 2 times the trapezoid's levels: 9.240 rising, -18.480 falling.
    assert acceleration.max() == pytest.approx(np.pi / 2 * v / TAU1, rel=1e-9)
    assert acceleration.min() == pytest.approx(-np.pi / 2 * v / (1 - TAU2), rel=1e-9)
    assert acceleration.max() == pytest.approx(9.239978, abs=1e-6)
    # Derivatives agree with finite differences.
    h = 1e-6
    inner = np.linspace(0.01, 0.99, 97)
    for order in range(3):
        numeric = (profile.derivatives(inner + h)[order] - profile.derivatives(inner - h)[order]) / (2 * h)
        assert profile.derivatives(inner)[order + 1] == pytest.approx(numeric, abs=1e-4)
    assert profile.tau_at(profile.derivatives(inner)[0]) == pytest.approx(inner, abs=1e-10)


def test_clamped_spline_matches_scipy_and_holds_a_cubic_exactly():
    points = np.linspace(0.0, 1.0, 9)
    values = np.sin(3 * points)
    spline = clamped_spline(values, 0.5, -1.0)
    reference = CubicSpline(points, values, bc_type=((1, 0.5), (1, -1.0)))
    for order in range(4):
        assert_close(spline.derivatives(FINE)[order], reference(FINE, order), 1e-9)
    # The rest-to-rest cubic 3 tau^2 - 2 tau^3 is its own spline.
    cubic = clamped_spline(3 * points**2 - 2 * points**3, 0.0, 0.0)
    assert_close(cubic.derivatives(FINE)[0], 3 * FINE**2 - 2 * FINE**3, 1e-12)


@pytest.mark.parametrize("law, points", [(TRAPEZOID, 8), (CycloidalProfile(), 6), (QuinticProfile(), 10)])
def test_spline_law_rests_at_both_ends_and_approximates_the_law(law, points):
    profile = SplineProfile(law, points)
    sigma, speed, acceleration, jerk = profile.derivatives(FINE)
    assert sigma[[0, -1]] == pytest.approx([0.0, 1.0], abs=1e-14)
    assert speed[[0, -1]] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert speed.min() >= -1e-12
    at_points = np.linspace(0.0, 1.0, points)
    assert profile.derivatives(at_points)[0] == pytest.approx(law.derivatives(at_points)[0], abs=1e-12)
    assert np.abs(sigma - law.derivatives(FINE)[0]).max() < 0.01
    assert np.isfinite(jerk).all()


def test_spline_law_refuses_too_few_points_for_a_sharp_law():
    """Five points of a cycloidal-blend trapezoid that reaches full speed in 0.1 % of the time:
    the spline overshoots and would move backwards."""
    with pytest.raises(ValueError, match="backwards"):
        SplineProfile(CycloidalBlendProfile(0.001, 0.001), 5)


UR5 = robots.load("ur5")
SERVED = [
    pytest.param({"name": "trapezoidal", "blend": "cycloidal"}, id="trapezoidal-cycloidal"),
    pytest.param({"name": "trapezoidal", "fractions": (TAU1, TAU2), "supporting_points": 8}, id="trapezoidal-spline8"),
    pytest.param({"name": "cycloidal", "supporting_points": 6}, id="cycloidal-spline6"),
    pytest.param({"name": "quintic", "supporting_points": 12}, id="quintic-spline12"),
]


@pytest.mark.parametrize("interpolation", ["spline", "linear"])
@pytest.mark.parametrize("options", SERVED)
def test_shortest_new_laws_hold_every_limit_and_are_not_faster_than_optimal(options, interpolation):
    # The clamped splines leave rest with sigma''(0) != 0, an acceleration step: no jerk limit.
    smooth = "supporting_points" not in options
    kinds = ("velocity", "acceleration", "torque", "jerk")[: 4 if smooth else 3]
    path = WaypointPath(np.array(UR5_WAYPOINTS), interpolation)
    if not smooth:
        with pytest.raises(InfeasiblePath) as refused:
            plan(build_problem(UR5, path, TimeLaw(**options).method(), limits=LimitRequest(kinds=(*kinds, "jerk"))))
        assert refused.value.limit == "jerk"
    result = plan(build_problem(UR5, path, TimeLaw(**options).method(), limits=LimitRequest(kinds=kinds)))
    optimal = plan(build_problem(UR5, path, METHODS["phase_plane"], limits=LimitRequest(kinds=kinds[:3])))
    assert result.duration >= optimal.duration
    for kind in kinds:
        assert result.peak_utilization[kind].max() <= 1.005, kind
    binding = result.binding
    joint = UR5.joint_names.index(binding.joint)
    assert 0.995 <= result.peak_utilization[binding.kind][joint] <= 1.005
    assert result.samples.qd[0] == pytest.approx(np.zeros(6), abs=1e-12)
    assert result.samples.qd[-1] == pytest.approx(np.zeros(6), abs=1e-9)
    assert result.samples.q[-1] == pytest.approx(UR5_WAYPOINTS[-1], abs=1e-9)


def test_single_joint_closed_form_of_the_cycloidal_blend():
    """One joint, acceleration limit a, distance L: T = sqrt(L pi s'_max / (2 a tau1)) with the
    default fractions 1/3, 2/3 (s'_max = 1.5)."""
    start = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])
    goal = start + np.array([1.2, 0, 0, 0, 0, 0])
    a = UR5.limits.acceleration[0]
    law = TimeLaw("trapezoidal", blend="cycloidal").method()
    result = plan(build_problem(UR5, WaypointPath(np.array([start, goal])), law, limits=LimitRequest(kinds=("acceleration",))))
    assert result.duration == pytest.approx(np.sqrt(1.2 * np.pi * 1.5 / (2 * a / 3)), rel=1e-6)


@pytest.mark.parametrize(
    "law, boundary, field, rule, fragment",
    [
        ({"name": "cubic", "blend": "cycloidal"}, {}, "law.blend", "blend_needs_trapezoidal", "timing.trapezoid.blend"),
        ({"name": "phase_plane", "supporting_points": 8}, {}, "law.supporting_points", "needs_time_law", "timing.supporting_points"),
        ({"name": "trapezoidal", "fractions": (0.001, 0.001), "blend": "cycloidal", "supporting_points": 5}, {},
         "law.supporting_points", "law_spline_failed", "backwards"),
        ({"name": "quintic", "supporting_points": 8}, {"start_velocity": np.full(6, 0.1)}, "law.supporting_points",
         "law_from_rest", "rest to rest"),
    ],
)
def test_law_options_refused_where_they_do_not_apply(law, boundary, field, rule, fragment):
    path = WaypointPath(np.array(UR5_WAYPOINTS[:2]))
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(UR5, path, TimeLaw(**law).method(), boundary=BoundaryStates(**boundary)))
    assert (refused.value.field, refused.value.rule) == (field, rule)
    assert fragment in detail(refused.value)


def test_laws_over_http(client):
    body = {
        "robot": "ur5",
        "path": {"waypoints": UR5_WAYPOINTS},
        "timing": {"method": "trapezoidal", "constraints": ["velocity", "acceleration", "jerk"],
                   "trapezoid": {"tau1": TAU1, "tau2": TAU2, "blend": "cycloidal"}},
        "output": {"dt": 0.01},
    }
    blended = client.post("/v1/trajectories", json=body)
    assert blended.status_code == 200, blended.text
    body["timing"]["trapezoid"]["blend"] = "linear"
    body["timing"]["supporting_points"] = 8
    stepped = client.post("/v1/trajectories", json=body)
    # The spline leaves rest with an acceleration step: no jerk limit holds.
    assert stepped.status_code == 422 and stepped.json()["limit"] == "jerk", stepped.text
    assert "spline through 8 points" in stepped.json()["detail"]
    body["timing"]["constraints"] = ["velocity", "acceleration"]
    spline = client.post("/v1/trajectories", json=body)
    assert spline.status_code == 200, spline.text
    body["timing"].pop("supporting_points")
    plain = client.post("/v1/trajectories", json=body)
    # Three different laws: three different durations, each within its limits.
    durations = {response.json()["duration"] for response in (blended, spline, plain)}
    assert len(durations) == 3
    for response in (blended, spline, plain):
        assert max(max(v) for v in response.json()["peak_utilization"].values() if v) <= 1.005
    body["timing"]["supporting_points"] = 3
    refused = client.post("/v1/trajectories", json=body)
    assert refused.status_code == 422 and "supporting_points" in refused.text


def test_supporting_points_refused_with_via_points():
    path = WaypointPath(np.array(UR5_WAYPOINTS), "via")
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(UR5, path, ViaPoints(TimeLaw("cubic", supporting_points=8).method())))
    assert (refused.value.field, refused.value.rule) == ("law.supporting_points", "via_points_are_polynomials")
    assert "leave timing.supporting_points out" in detail(refused.value)
