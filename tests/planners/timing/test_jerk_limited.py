"""``timing.method = "jerk_limited"``: time-optimal along the given path under velocity,
acceleration, torque and jerk limits. Checked against the closed-form jerk-limited profile,
against ruckig on straight joint lines, and on seeded random spline paths of ur5 and panda by
the limits recomputed from the returned samples."""

from __future__ import annotations

import numpy as np
import pytest
from ruckig import InputParameter, Ruckig, Trajectory

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.errors import TimingFailed
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.timing.jerk.method import JerkLimitedMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.service.problems import status_of

JERK_KINDS = ("velocity", "acceleration", "jerk")
#: Relative agreement with ruckig on straight lines, where both are the exact optimum.
RUCKIG_AGREEMENT = 3e-6


@pytest.mark.parametrize(
    "robot, joint, length, limits",
    [
        ("ur5", 0, 2.0, None),
        ("ur5", 2, 1.5, {"velocity": 1.2, "acceleration": 4.0, "jerk": 30.0}),
        ("panda", 3, -1.0, {"velocity": 0.8, "acceleration": 5.0, "jerk": 400.0}),
    ],
)
def test_one_joint_rest_to_rest_is_the_closed_form_profile(robot, joint, length, limits):
    """One joint moving L from rest to rest, long enough for the profile to reach the velocity
    and the acceleration limit: T = L / v + v / a + a / j, within 1e-6."""
    arm = robots.load(robot)
    start = np.clip(np.zeros(arm.dof), arm.limits.position_lower, arm.limits.position_upper)
    start[joint] = 0.5 * (arm.limits.position_lower[joint] + arm.limits.position_upper[joint]) - length / 2
    goal = start.copy()
    goal[joint] += length
    overrides = {}
    if limits:
        for kind, value in limits.items():
            vector = getattr(arm.limits, kind).copy()
            vector[joint] = value
            overrides[kind] = vector.tolist()
    requested = arm.limits.with_request(overrides)
    v, a, j = requested.velocity[joint], requested.acceleration[joint], requested.jerk[joint]
    assert v > a * a / j and abs(length) > v * (v / a + a / j)  # both limits are reached
    result = plan(build_problem(arm, WaypointPath(np.array([start, goal])), METHODS["jerk_limited"], limits=LimitRequest(kinds=JERK_KINDS, overrides=overrides), sampling=Sampling(dt=1e-3)))
    expected = abs(length) / v + v / a + a / j
    assert result.duration == pytest.approx(expected, rel=1e-6)
    assert result.samples.q[-1] == pytest.approx(goal, abs=1e-9)


def _ruckig_duration(arm, start, goal, limits) -> float:
    """ruckig's time-optimal phase-synchronized duration between two states at rest."""
    inputs = InputParameter(arm.dof)
    inputs.current_position, inputs.target_position = start.tolist(), goal.tolist()
    inputs.max_velocity = limits.velocity.tolist()
    inputs.max_acceleration = limits.acceleration.tolist()
    inputs.max_jerk = limits.jerk.tolist()
    from ruckig import Synchronization

    inputs.synchronization = Synchronization.Phase
    trajectory = Trajectory(arm.dof)
    Ruckig(arm.dof).calculate(inputs, trajectory)
    return trajectory.duration


@pytest.mark.parametrize("seed", range(5))
def test_straight_ur5_lines_match_ruckig(seed):
    """Straight joint lines: jerk_limited within 3e-6 of ruckig's phase-synchronized duration
    (the time-optimal motion that keeps every joint on the line) and never shorter. Both are
    the exact optimum (the double-S profile in closed form or polished in time; Berscheid &
    Kroeger's along the line), so the tolerance is the polish's accuracy, not a grid's."""
    arm = robots.load("ur5")
    rng = np.random.default_rng(seed)
    start, goal = rng.uniform(-2.0, 2.0, size=(2, arm.dof))
    scale = rng.uniform(0.3, 1.0)
    result = plan(build_problem(arm, WaypointPath(np.array([start, goal])), METHODS["jerk_limited"], limits=LimitRequest(kinds=JERK_KINDS, scales={"jerk": scale}), sampling=Sampling(dt=0.01)))
    reference = _ruckig_duration(arm, start, goal, arm.limits.with_request(scales={"jerk": scale}))
    assert result.duration == pytest.approx(reference, rel=RUCKIG_AGREEMENT)
    assert result.duration >= reference * (1 - 1e-9)


def _random_spline(arm, rng) -> np.ndarray:
    lower, upper = arm.limits.position_lower, arm.limits.position_upper
    middle, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
    return rng.uniform(middle - 0.3 * half, middle + 0.3 * half, size=(4, arm.dof))


def _recomputed_peaks(arm, samples) -> dict[str, np.ndarray]:
    """Peak |value| per joint from the samples: velocity, acceleration and torque as returned
    (torque recomputed by RNEA), jerk by finite differences of the accelerations."""
    t = samples.t
    jerk = np.diff(samples.qdd, axis=0) / np.diff(t)[:, None]
    torque = arm.inverse_dynamics(samples.q, samples.qd, samples.qdd)
    return {
        "velocity": np.abs(samples.qd).max(axis=0),
        "acceleration": np.abs(samples.qdd).max(axis=0),
        "torque": np.abs(torque).max(axis=0),
        "jerk": np.abs(jerk).max(axis=0),
    }


def _torque_scale(arm, waypoints) -> float:
    """A torque scale at which holding the arm still along the path takes 1 / 1.3 of the
    limit somewhere: the torque limit then shapes the motion."""
    q = make_path(arm, WaypointPath(waypoints))(np.linspace(0.0, 1.0, 400))
    gravity = np.abs(arm.inverse_dynamics(q, np.zeros_like(q), np.zeros_like(q))) / arm.limits.torque
    return min(1.0, 1.3 * float(gravity.max()))


@pytest.mark.parametrize("robot, seed", [("ur5", 0), ("ur5", 1), ("panda", 0), ("panda", 1)])
def test_random_splines_hold_torque_and_jerk_limits(robot, seed):
    """With torque limits scaled down until they shape the motion: every limit within 0.5 % on
    a dense resampling (0.25 ms samples, torque by RNEA, jerk by finite differences of the
    accelerations: the grid refined to its 0.1 % gap has peaks of jerk shorter than 1 ms, which
    1 ms differences would average away); the jerk from the samples agrees with the reported peak of every joint; the
    duration is at least the jerk-free optimum (phase_plane, to its accuracy of 0.1 %)."""
    arm = robots.load(robot)
    waypoints = _random_spline(arm, np.random.default_rng(100 + seed))
    scales = {"torque": _torque_scale(arm, waypoints)}
    result = plan(build_problem(arm, WaypointPath(waypoints), METHODS["jerk_limited"], limits=LimitRequest(kinds=("velocity", "acceleration", "torque", "jerk"), scales=scales), sampling=Sampling(dt=2.5e-4)))
    limits = arm.limits.with_request(scales=scales)
    peaks = _recomputed_peaks(arm, result.samples)
    for kind, peak in peaks.items():
        limit = getattr(limits, kind)
        finite = np.isfinite(limit)
        assert (peak[finite] / limit[finite]).max() <= 1.005, kind
        assert result.peak_utilization[kind].max() <= 1.005, kind
    # The jerk binds, the torque comes close to its limit, and the samples show the jerk the
    # answer reports on every joint (their differences average it over 0.25 ms: never above it).
    reported = result.peak_utilization["jerk"] * limits.jerk
    assert result.peak_utilization["jerk"].max() > 0.99
    assert result.peak_utilization["torque"].max() > 0.9
    assert np.all(peaks["jerk"] <= reported * (1 + 1e-3))
    assert np.all(peaks["jerk"] >= 0.98 * reported)
    jerk_free = plan(build_problem(arm, WaypointPath(waypoints), METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity", "acceleration", "torque"), scales=scales), sampling=Sampling(dt=0.01)))
    assert result.duration >= jerk_free.duration * (1 - 1e-3)


def test_jerk_limited_over_http(client):
    """The method by name: the jerk constraint is added when not listed, stop-and-go paths are
    timed stretch by stretch, and the answer reports the jerk's utilization."""
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:3], "interpolation": "linear"},
        "timing": {"method": "jerk_limited", "constraints": ["velocity", "acceleration", "torque"]},
        "output": {"dt": 0.005},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    assert result["method"] == "jerk_limited"
    assert 0.99 < max(result["peak_utilization"]["jerk"]) <= 1.003
    qd = np.array(result["samples"]["qd"])
    assert np.linalg.norm(qd[len(qd) // 2 - 50 : len(qd) // 2 + 50], axis=1).min() < 0.1  # it stops at the corner


def test_jerk_limited_refuses_boundary_accelerations(client):
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:2]},
        "timing": {"method": "jerk_limited", "boundary": {"start_acceleration": [0.1] * 6}},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert "quintic" in response.json()["detail"]


def test_a_blended_path_with_a_jerk_limit_is_refused_where_its_curvature_jumps(client):
    """Where a straight segment meets a circular blend, d2q/ds2 jumps: the joint accelerations
    jump with it unless the motion stops, so no jerk limit can hold (422 naming the place)."""
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:3], "interpolation": "blend", "max_deviation": 0.1},
        "timing": {"method": "jerk_limited"},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    problem = response.json()
    assert problem["limit"] == "jerk"
    assert 0.0 < problem["s"] < 1.0
    assert "spline" in problem["detail"]


def test_the_gate_refuses_samples_whose_accelerations_jump(monkeypatch):
    """The gate's last check reads the returned samples: a jerk_limited answer whose
    accelerations jump (here the jerk-free optimum in its place) is refused, naming the jerk
    limit and the time."""
    def bang_bang(self, constraints, boundary, duration=None, deadline=None):
        return PhasePlaneMethod().solve(constraints, boundary)

    monkeypatch.setattr(JerkLimitedMethod, "solve", bang_bang)
    arm = robots.load("ur5")
    with pytest.raises(TimingFailed, match="jerk limit of joint") as raised:
        plan(build_problem(arm, WaypointPath(np.array(UR5_WAYPOINTS[:2])), METHODS["jerk_limited"], sampling=Sampling(dt=1e-3)))
    assert status_of(raised.value) == 422
    assert "t = " in raised.value.detail


@pytest.mark.parametrize("method", ["jerk_limited", "phase_plane", "toppra", "quintic"])
def test_a_torque_limit_below_gravity_is_refused_with_where_and_which(client, method):
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:2]},
        "timing": {"method": method, "limits": {"torque_scale": 0.05}},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    problem = response.json()
    assert "torque" in problem["detail"] and problem["joint"] and 0.0 <= problem["s"] <= 1.0
    assert problem["limit"] == "torque"


@pytest.mark.parametrize(
    "timing, fragment",
    [
        ({"method": "jerk_limited", "duration": 2.0}, "duration"),
        ({"method": "jerk_limited", "limits": {"jerk": [0.0] * 6}}, "jerk"),
        ({"method": "jerk_limited", "limits": {"jerk": [100.0] * 5}}, "jerk"),
        ({"method": "jerk_limited", "constraints": ["jerk", "snap"]}, "constraints"),
    ],
)
def test_bad_jerk_limited_requests_get_a_clear_4xx(client, timing, fragment):
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:2]}, "timing": timing}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    assert fragment in response.text


def test_a_start_whose_constant_jerk_phase_is_tiny_holds_the_jerk_limit():
    """A panda spline whose torque limit (gravity takes 1 / 1.3 of it) leaves a path
    acceleration at rest that its jerk reaches within 1e-7 of s: the jerk rows there are of the
    size of x (1e-8 of its typical value), and must hold to the solver's tolerance (they were
    exceeded by 41 %, and by 2,000 % after the gate's refinements, with the LP's default one)."""
    arm = robots.load("panda")
    waypoints = np.array([
        [-0.7745, 0.2691, -0.1837, -1.3722, 1.0376, 2.3347, 1.4119],
        [-0.7229, -0.4481, -0.2572, -0.88, 1.6976, 2.5458, 0.1529],
        [1.8497, -0.1966, -1.1331, -1.0701, 1.8604, 1.6073, -0.769],
    ])
    scales = {"torque": _torque_scale(arm, waypoints)}
    result = plan(build_problem(arm, WaypointPath(waypoints), METHODS["jerk_limited"], limits=LimitRequest(kinds=("velocity", "acceleration", "torque", "jerk"), scales=scales), sampling=Sampling(dt=1e-3)))
    limits = arm.limits.with_request(scales=scales)
    peaks = _recomputed_peaks(arm, result.samples)
    for kind, peak in peaks.items():
        assert (peak / getattr(limits, kind)).max() <= 1.005, kind


def test_jerk_limits_from_the_request_are_held_over_http(client):
    """``timing.limits.jerk`` replaces the robot's jerk limits: the samples' jerk (finite
    differences) stays within them, reaches them, and the motion takes longer than under the
    robot's own."""
    jerk = [40.0, 30.0, 40.0, 60.0, 60.0, 60.0]
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:3]},
        "timing": {"method": "jerk_limited", "constraints": ["velocity", "acceleration", "torque", "jerk"]},
        "output": {"dt": 1e-3},
    }
    default = client.post("/v1/trajectories", json=body)
    body["timing"]["limits"] = {"jerk": jerk}
    limited = client.post("/v1/trajectories", json=body)
    assert default.status_code == 200 and limited.status_code == 200, limited.text
    samples = limited.json()["samples"]
    differences = np.diff(np.array(samples["qdd"]), axis=0) / np.diff(samples["t"])[:, None]
    ratio = np.abs(differences).max(axis=0) / np.array(jerk)
    assert ratio.max() <= 1.005
    assert ratio.max() > 0.98
    assert max(limited.json()["peak_utilization"]["jerk"]) == pytest.approx(ratio.max(), rel=0.01)
    assert limited.json()["duration"] > default.json()["duration"]


def test_positions_follow_the_velocities_where_the_path_speed_grows_many_fold_in_one_interval():
    """z1 leaving a nearly repeated waypoint: on the interval after the one at rest x = sd^2 grew
    44,000 fold, where 12 Gauss-Legendre nodes put its time 0.055 % (69 us) too long; the
    samples' positions then lagged their velocities, a jump of 6e-7 rad at the interval's end
    (1.25 times the acceleration limit seen by differencing the positions). Over every sample
    pair, the positions' step now equals the velocities' trapezoid within the trapezoid rule's own
    error, dt^3 |jerk| / 12, the jerk held to its limit."""
    from toptraj.service.planning import plan_request
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    body = {
        "robot": "z1",
        "path": {"waypoints": [[-0.323877, 0.971782, -0.117204, -1.323393, -0.348684, 1.567179],
                               [-0.323875, 0.971781, -0.117203, -1.323389, -0.348686, 1.567178],
                               [-2.198344, 0.34406, -1.031142, -0.072382, 0.944312, 2.195181]],
                 "min_spacing": 0},
        "timing": {"method": "jerk_limited", "constraints": ["velocity", "acceleration", "torque", "jerk"],
                   "limits": {"velocity_scale": 0.981}},
        "output": {"dt": 0.0005},
    }
    answer = plan_request(TrajectoryRequest.model_validate(body))
    t, q, qd = answer.samples.t, answer.samples.q, answer.samples.qd
    step = np.diff(t)[:, None]
    residual = np.abs(np.diff(q, axis=0) - 0.5 * (qd[1:] + qd[:-1]) * step)
    jerk_limit = robots.load("z1").limits.jerk
    assert np.all(residual <= 1.005 * step**3 * jerk_limit / 12.0 + 1e-12)


def test_a_grid_solved_for_the_estimate_that_stops_mid_path_leaves_the_gap_unstated_with_advice_that_works():
    """Geering's arm ending on two waypoints 4e-5 rad apart: grids solved for the estimate stop the
    motion inside the path (infinite durations), the gap came out NaN and the answer was refused
    as "not representable". The answer stands with no gap, saying why; the advice (more grid
    points) gives one."""
    from toptraj.service.planning import plan_request
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    body = {
        "robot": "geering_2r",
        "path": {"waypoints": [[1.5200490308855918, -1.3187796758833268], [1.888342032802192, -1.3481432432491909],
                               [2.710646690223219, -1.2029718320976668], [2.7106706186076357, -1.2029408588577613]],
                 "min_spacing": 0},
        "timing": {"method": "jerk_limited", "constraints": ["velocity", "acceleration", "torque", "jerk"]},
        "output": {"dt": 0.001},
    }
    answer = plan_request(TrajectoryRequest.model_validate(body))
    assert answer.accuracy.relative_gap is None and "stops the motion inside the path" in answer.accuracy.basis
    followed = plan_request(TrajectoryRequest.model_validate({**body, "timing": {**body["timing"], "grid_points": 1000}}))
    assert followed.accuracy.relative_gap is not None and followed.accuracy.relative_gap < 1e-3
