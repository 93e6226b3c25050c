"""The lecture "Trajectory Planning": non-normalized and normalized joint moves of its 2-DOF arm
(``timing.synchronization``), and the quintic's peak acceleration in its Example 2.

The lecture's arm is a planar two-link arm with joint angles alpha (lower link) and beta (upper
link) and no dynamics given. The bundled ``geering_2r`` is such an arm (horizontal, so gravity
plays no part; joints ``phi`` and ``psi``); its catalog sets no velocity limit, so the tests set
the lecture's 10 deg/s on both joints. ``lecture_3r`` is the lecture's other robot (the 3-DOF
laboratory arm of the Cartesian example), with three joints and 2 rad/s limits: not this one.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners import METHODS, BoundaryStates, LimitRequest, Sampling, TimeLaw, WaypointPath, build_problem, plan
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.generators.joint_moves import Unsynchronized
from toptraj.planners.timing.laws.profiles import QuinticProfile, polynomial_derivatives, quintic_coefficients
from toptraj.service.problems import detail

ARM = robots.load("geering_2r")
A = np.radians([20.0, 30.0])
B = np.radians([40.0, 80.0])
SPEED = np.radians(10.0)


def lecture_problem(path, synchronization, dt, **options):
    """The lecture's constant-speed moves: a trapezoid that accelerates in 0.1 % of the time under
    a high acceleration limit (1000 rad/s^2); every joint on its own with ``synchronization``
    ``"none"``, in step otherwise."""
    law = TimeLaw("trapezoidal", fractions=(0.001, 0.999)).method()
    limits = LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [SPEED, SPEED], "acceleration": [1000.0, 1000.0]})
    method = Unsynchronized(law) if synchronization == "none" else law
    return build_problem(ARM, path, method, limits=limits, sampling=Sampling(dt), **options)


def finish_times(result, goal):
    """When each joint reaches its goal (s), to the sample."""
    arrived = np.abs(result.samples.q - goal) < 1e-9
    return np.array([result.samples.t[np.argmax(arrived[:, j])] for j in range(goal.size)])


def test_non_normalized_each_joint_at_its_own_full_speed():
    """Alpha is done at 2 s, beta at 5 s, both at 10 deg/s (the trapezoid's cruise is 1.001 times
    the mean speed and its ramps 0.1 % of the time: within 0.2 % of the constant-speed times)."""
    result = plan(lecture_problem(WaypointPath(np.array([A, B])), "none", 0.001))
    assert result.duration == pytest.approx(5.0, rel=2e-3)
    assert finish_times(result, B) == pytest.approx([2.0, 5.0], rel=2e-3)
    mid = np.searchsorted(result.samples.t, 1.0)
    assert np.degrees(result.samples.qd[mid]) == pytest.approx([10.0, 10.0], rel=1e-9)
    late = np.searchsorted(result.samples.t, 3.0)
    assert np.degrees(result.samples.qd[late]) == pytest.approx([0.0, 10.0], abs=1e-9)
    assert result.binding.kind == "velocity" and result.binding.joint == "psi"
    # The path bends: at 2 s alpha has arrived but beta has gone only 20 of its 50 degrees.
    at_two = np.searchsorted(result.samples.t, 2.1)
    share = (result.samples.q[at_two] - A) / (B - A)
    assert share[0] == pytest.approx(1.0) and share[1] == pytest.approx(0.42, abs=3e-3)
    assert max(result.peak_utilization["velocity"]) == pytest.approx(1.0, abs=1e-9)


def test_normalized_both_joints_stop_together():
    """Alpha at 4 deg/s, beta at 10 deg/s, both done at 5 s, along the straight joint line; the
    default, as before."""
    normalized = plan(lecture_problem(WaypointPath(np.array([A, B])), "normalized", 0.001))
    default = plan(build_problem(
        ARM, WaypointPath(np.array([A, B])), TimeLaw("trapezoidal", fractions=(0.001, 0.999)).method(),
        limits=LimitRequest(kinds=("velocity", "acceleration"), overrides={"velocity": [SPEED, SPEED], "acceleration": [1000.0, 1000.0]}),
        sampling=Sampling(0.001),
    ))
    assert normalized.duration == pytest.approx(5.0, rel=2e-3)
    assert finish_times(normalized, B) == pytest.approx([normalized.duration] * 2, abs=1e-3)
    mid = np.searchsorted(normalized.samples.t, 1.0)
    assert np.degrees(normalized.samples.qd[mid]) == pytest.approx([4.0, 10.0], rel=1e-9)
    share = (normalized.samples.q - A) / (B - A)
    assert share[:, 0] == pytest.approx(share[:, 1], abs=1e-12)
    assert default.duration == normalized.duration


@pytest.mark.parametrize("law", ["cubic", "quintic", "trapezoidal", "cycloidal"])
def test_non_normalized_laws_hold_every_limit_and_end_at_rest(law):
    """Each joint alone is as short as its limits allow: its own duration is the closed form
    (D sigma'_max / v, sqrt(D sigma''_max / a), cbrt(D sigma'''_max / j)), the slowest sets the
    total, and the motion holds every limit (torque included, by a common stretch)."""
    # The cubic and the trapezoid have acceleration steps, so no jerk limit for them.
    kinds = ("velocity", "acceleration", "jerk", "torque") if law in ("quintic", "cycloidal") else ("velocity", "acceleration", "torque")
    limits = {"velocity": [SPEED, 2 * SPEED], "acceleration": [0.5, 0.3], "jerk": [5.0, 5.0]}
    asked = LimitRequest(kinds=kinds, overrides=limits)
    result = plan(build_problem(ARM, WaypointPath(np.array([A, B])), Unsynchronized(METHODS[law]), limits=asked, sampling=Sampling(0.002)))
    assert result.samples.qd[0] == pytest.approx([0, 0], abs=1e-12)
    assert result.samples.qd[-1] == pytest.approx([0, 0], abs=1e-9)
    assert result.samples.q[-1] == pytest.approx(B, abs=1e-12)
    for kind in kinds:
        assert max(result.peak_utilization[kind]) <= 1.005, kind
    assert max(result.peak_utilization[result.binding.kind]) >= 0.995
    normalized = plan(build_problem(ARM, WaypointPath(np.array([A, B])), METHODS[law], limits=asked))
    # Moving alone, the slowest joint is never slower than with the other one in step.
    assert result.duration <= normalized.duration * (1 + 1e-6)


def test_torque_stretches_the_joints_together():
    """Torque couples the joints: 1 N m on the shoulder stretches both own durations by one
    factor, until the torque binds."""
    limits = LimitRequest(kinds=("velocity", "torque"), overrides={"velocity": [SPEED, SPEED], "torque": [1.0, 1.0]})
    method = Unsynchronized(METHODS["cycloidal"])
    result = plan(build_problem(ARM, WaypointPath(np.array([A, B])), method, limits=limits, sampling=Sampling(0.002)))
    assert result.binding.kind == "torque"
    assert max(result.peak_utilization["torque"]) == pytest.approx(1.0, abs=5e-3)
    assert result.duration > 2 * 50 / 10  # beyond the cycloid's 2 D / v = 10 s at full speed


def test_given_duration_sets_the_slowest_joint():
    result = plan(lecture_problem(WaypointPath(np.array([A, B])), "none", 0.001, duration=10.0))
    assert result.duration == pytest.approx(10.0, abs=1e-12)
    assert finish_times(result, B) == pytest.approx([4.0, 10.0], abs=2e-3)
    assert result.binding is None


@pytest.mark.parametrize(
    "path, method, options, rule, fragment",
    [
        (np.array([A, (A + B) / 2, B]), "trapezoidal", {}, "unsynchronized_needs_two_waypoints", "exactly 2 waypoints"),
        (np.array([A, B]), "trapezoidal", {"boundary": BoundaryStates(start_velocity=B - A)}, "unsynchronized_from_rest", "rest to rest"),
        (np.array([A, B]), "phase_plane", {}, "unsynchronized_needs_law", "time law"),
        (np.array([A, B]), "trapezoidal", {"kinds": ("torque",)}, "unsynchronized_needs_a_limit", "velocity, acceleration or jerk"),
    ],
)
def test_non_normalized_refusals(path, method, options, rule, fragment):
    kinds = options.pop("kinds", ("velocity", "acceleration", "torque"))
    limits = LimitRequest(kinds=kinds, overrides={"velocity": [SPEED, SPEED]})
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(ARM, WaypointPath(path), Unsynchronized(METHODS[method]), limits=limits, **options))
    assert (refused.value.field, refused.value.value, refused.value.rule) == ("law.synchronization", "none", rule)
    assert fragment in detail(refused.value)


def test_unlimited_joint_is_named():
    """geering_2r with a velocity limit on psi only: phi, moving on its own, has none, and the
    error names it (without any, the problem is refused before: nothing bounds the motion)."""
    limits = LimitRequest(kinds=("velocity",))
    arm = dataclasses.replace(ARM, limits=dataclasses.replace(ARM.limits, velocity=np.array([np.inf, 2.0])))
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(arm, WaypointPath(np.array([A, B])), Unsynchronized(METHODS["trapezoidal"]), limits=limits))
    assert (refused.value.rule, refused.value.joint_name) == ("unsynchronized_joint_unlimited", "phi")
    assert "'phi'" in detail(refused.value)
    with pytest.raises(InvalidRequest) as refused:
        build_problem(ARM, WaypointPath(np.array([A, B])), Unsynchronized(METHODS["trapezoidal"]), limits=limits)
    assert refused.value.rule == "no_limit_bounds_speed"


def test_lecture_over_http(client):
    body = {
        "robot": "geering_2r",
        "path": {"waypoints": [A.tolist(), B.tolist()]},
        "timing": {
            "method": "trapezoidal",
            "constraints": ["velocity", "acceleration"],
            "limits": {"velocity": [SPEED, SPEED], "acceleration": [1000.0, 1000.0]},
            "trapezoid": {"tau1": 0.001, "tau2": 0.999},
            "synchronization": "none",
        },
        "output": {"dt": 0.5},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    samples = response.json()["samples"]
    assert response.json()["duration"] == pytest.approx(5.0, rel=2e-3)
    # At 2.5 s alpha is at its goal and beta half-way (and a bit, 25 of 50 degrees).
    index = samples["t"].index(2.5)
    assert np.degrees(samples["q"][index]) == pytest.approx([40.0, 55.0], abs=0.05)
    body["timing"]["synchronization"] = "normalized"
    together = client.post("/v1/trajectories", json=body).json()["samples"]
    assert np.degrees(together["q"][together["t"].index(2.5)]) == pytest.approx([30.0, 55.0], abs=0.05)
    body["timing"]["synchronization"] = "sideways"
    assert client.post("/v1/trajectories", json=body).status_code == 422


def test_example_2_quintic_peak_acceleration():
    """Example 2: 30 deg to 75 deg in 5 s, starting at 5 deg/s^2 and ending at -5 deg/s^2. The
    lecture reads the peak off its plot as 8.7 deg/s^2, below the cubic's 6 (75 - 30) / 5^2 =
    10.8. Our quintic with those boundary accelerations peaks at 8.7039 deg/s^2 (t = 0.826 s),
    the lecture's value. The lecture's printed acceleration, 5 + 9.6 t - 6.9 t^2 + 0.928 t^3,
    rounds 12 c4 = -6.96 to -6.9 and would peak at 8.745. Our ``quintic`` time law without
    boundary accelerations (the rest-to-rest 10 tau^3 - 15 tau^4 + 6 tau^5) peaks at
    10 / sqrt(3) 45 / 25 = 10.392 deg/s^2, still below the cubic's 10.8."""
    coefficients = quintic_coefficients(30.0, 0.0, 5.0, 75.0, 0.0, -5.0, 5.0)
    t = np.linspace(0.0, 5.0, 500_001)
    acceleration = polynomial_derivatives(coefficients, t, 3)[2]
    assert acceleration.max() == pytest.approx(8.7, abs=0.05)
    assert acceleration.max() == pytest.approx(8.703943, abs=1e-6)
    assert t[np.argmax(acceleration)] == pytest.approx(0.826, abs=1e-3)
    assert acceleration.min() == pytest.approx(-8.703943, abs=1e-6)
    printed = 5 + 9.6 * t - 6.9 * t**2 + 0.928 * t**3
    assert printed.max() == pytest.approx(8.745, abs=1e-3)
    tau = np.linspace(0.0, 1.0, 100_001)
    rest_to_rest = 45.0 / 25.0 * np.abs(QuinticProfile().derivatives(tau)[2]).max()
    assert rest_to_rest == pytest.approx(10.0 / np.sqrt(3.0) * 45.0 / 25.0, rel=1e-9)
    assert rest_to_rest < 10.8
    # The same through the planner: one joint of the arm, 45 degrees in 5 s.
    start = np.radians([30.0, 0.0])
    goal = np.radians([75.0, 0.0])
    direction = np.array([1.0, 0.0])
    boundary = BoundaryStates(start_acceleration=np.radians(5.0) * direction, end_acceleration=np.radians(-5.0) * direction)
    result = plan(build_problem(
        ARM, WaypointPath(np.array([start, goal])), METHODS["quintic"], limits=LimitRequest(kinds=("velocity",), overrides={"velocity": [1.0, 1.0]}),
        boundary=boundary, duration=5.0, sampling=Sampling(0.001),
    ))
    assert np.degrees(result.samples.qdd[:, 0]).max() == pytest.approx(8.703943, abs=1e-4)
