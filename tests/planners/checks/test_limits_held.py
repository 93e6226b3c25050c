"""The core promise: a 200 never breaks a requested limit by more than 0.5 % on a dense
resampling, whatever the path (tiny segments included), the robot (1 to 7 joints) and the
method; with a positive ``timing.limit_margin`` no returned sample exceeds any limit.

Every check here reads the returned samples only (independently of the service's own dense
check): the joint velocities, accelerations and torques at a fine ``dt``, and the joint
accelerations again as finite differences of the returned velocities.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from tests.paths import DATA
from toptraj import robots
from toptraj.planners import METHODS as TIMING_METHODS
from toptraj.planners import LimitRequest, Sampling, WaypointPath, build_problem
from toptraj.planners import plan as plan_library

KINDS = ("velocity", "acceleration", "torque")
METHODS = ("phase_plane", "toppra", "min_cost", "quintic", "trapezoidal", "jerk_limited")


@pytest.fixture(scope="module")
def uploaded(client):
    """The uploaded 1- and 2-joint test arms, by file stem."""
    names = {}
    for stem in ("pendulum_1r", "lift_rp"):
        response = client.post("/v1/robots", json={"name": stem, "urdf": (DATA / f"{stem}.urdf").read_text()})
        assert response.status_code in (200, 201), response.text
        names[stem] = response.json()["name"]
    return names


def robot_limits(client, name: str) -> dict[str, np.ndarray]:
    limits = client.get(f"/v1/robots/{name}").json()["limits"]
    return {kind: np.array([np.inf if v is None else v for v in values]) for kind, values in limits.items()}


def random_waypoints(limits, rng, count: int, tiny_first: bool) -> list[list[float]]:
    lower = np.where(np.isfinite(limits["position_lower"]), limits["position_lower"], -np.pi)
    upper = np.where(np.isfinite(limits["position_upper"]), limits["position_upper"], np.pi)
    middle, half = 0.5 * (lower + upper), 0.3 * (upper - lower)
    points = [middle + rng.uniform(-1, 1, len(lower)) * half]
    if tiny_first:
        # A recorded path: the first two steps are tiny next to the rest (2e-4 and 1.6e-4 of
        # a 3 rad path, as in the data shipped with toppra's tests).
        for fraction in (2e-4, 1.6e-4):
            step = rng.normal(size=len(lower))
            points.append(points[-1] + 3.0 * fraction * step / np.linalg.norm(step))
    while len(points) < count:
        points.append(np.clip(points[-1] + rng.uniform(-1, 1, len(lower)) * half, middle - half, middle + half))
    return np.array(points).tolist()


def worst_ratio(body: dict, limits: dict[str, np.ndarray]) -> tuple[float, str]:
    """Largest |value| / limit over the returned samples, and of which kind."""
    samples = {key: np.array(value) for key, value in body["samples"].items()}
    t = samples["t"]
    steps = np.diff(t)
    values = {"velocity": samples["qd"], "acceleration": samples["qdd"], "torque": samples["tau"]}
    ratios = {kind: np.max(np.abs(value) / limits[kind]) for kind, value in values.items()}
    # Finite differences of the velocities average the acceleration over each step.
    even = steps > 0.5 * np.median(steps)
    differences = np.diff(samples["qd"], axis=0)[even] / steps[even][:, None]
    ratios["acceleration (differences)"] = np.max(np.abs(differences) / limits["acceleration"])
    if body["method"] == "jerk_limited":
        # Its accelerations are continuous: their differences average the jerk over each step.
        jerk = np.diff(samples["qdd"], axis=0)[even] / steps[even][:, None]
        ratios["jerk (differences)"] = np.max(np.abs(jerk) / limits["jerk"])
    kind = max(ratios, key=ratios.get)
    return float(ratios[kind]), kind


def plan(client, robot, waypoints, method, interpolation="spline", **timing):
    body = {
        "robot": robot,
        "path": {"kind": "waypoints", "waypoints": waypoints, "interpolation": interpolation},
        "timing": {"method": method, "constraints": list(KINDS), **timing},
        "output": {"dt": 1e-3},
    }
    return client.post("/v1/trajectories", json=body)


CASES = [
    ("pendulum_1r", 0), ("pendulum_1r", 1), ("lift_rp", 2), ("lift_rp", 3), ("yamamoto_2r", 4),
    ("lecture_3r", 5), ("ur5", 6), ("ur5", 7), ("panda", 8), ("panda", 9),
]


@pytest.mark.parametrize(("robot", "seed"), CASES)
def test_every_answer_holds_its_limits(client, uploaded, robot, seed):
    name = uploaded.get(robot, robot)
    limits = robot_limits(client, name)
    rng = np.random.default_rng(seed)
    answered = 0
    for case in range(len(METHODS)):
        method = METHODS[(seed + case) % len(METHODS)]
        waypoints = random_waypoints(limits, rng, int(rng.integers(3, 6)), tiny_first=case % 2 == 0)
        interpolation = "linear" if case == 3 else "spline"
        response = plan(client, name, waypoints, method, interpolation)
        assert response.status_code in (200, 422), response.text
        if response.status_code == 422:
            assert response.headers["content-type"].startswith("application/problem+json")
            continue
        answered += 1
        ratio, kind = worst_ratio(response.json(), limits)
        assert ratio <= 1.005, (method, interpolation, kind, ratio)
    assert answered >= len(METHODS) - 1


@pytest.mark.parametrize(("robot", "seed"), [("lift_rp", 11), ("ur5", 12), ("panda", 13)])
def test_a_positive_margin_keeps_every_sample_within_the_limits(client, uploaded, robot, seed):
    name = uploaded.get(robot, robot)
    limits = robot_limits(client, name)
    rng = np.random.default_rng(seed)
    for method in ("phase_plane", "toppra", "min_cost", "cycloidal", "jerk_limited"):
        waypoints = random_waypoints(limits, rng, 4, tiny_first=True)
        response = plan(client, name, waypoints, method, limit_margin=0.002)
        assert response.status_code == 200, response.text
        ratio, kind = worst_ratio(response.json(), limits)
        assert ratio <= 1.0, (method, kind, ratio)
        utilization = response.json()["peak_utilization"]
        assert max(max(utilization[kind]) for kind in KINDS) <= 1.0


def test_the_margin_is_kept_in_reserve(client):
    waypoints = [[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [1.0, -0.8, 1.4, -0.5, 0.9, 0.3]]
    full = plan(client, "ur5", waypoints, "phase_plane").json()
    reserved = plan(client, "ur5", waypoints, "phase_plane", limit_margin=0.1).json()
    peak = max(max(full["peak_utilization"][kind]) for kind in KINDS)
    peak_reserved = max(max(reserved["peak_utilization"][kind]) for kind in KINDS)
    assert peak == pytest.approx(1.0, abs=3e-3)
    assert peak_reserved == pytest.approx(0.9, abs=3e-3)
    assert reserved["duration"] > full["duration"]


@pytest.mark.parametrize("length", [0.004, 1e-3, 1e-6])
def test_stop_and_go_paths_with_a_short_segment_are_timed(client, length):
    """Stopping at every waypoint is always feasible, however short a segment is."""
    start = np.array([0.0, -1.2, 1.0, 0.0, 0.5, 0.0])
    middle = start + np.array([1.0, 0.3, -0.2, 0.4, 0.1, 0.2])
    short = middle + length * np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    end = short + np.array([0.5, -0.4, 0.3, -0.2, 0.3, 0.1])
    waypoints = [start.tolist(), middle.tolist(), short.tolist(), end.tolist()]
    for method in ("phase_plane", "toppra", "min_cost", "trapezoidal", "jerk_limited"):
        response = plan(client, "ur5", waypoints, method, interpolation="linear")
        assert response.status_code == 200, (method, response.text)
        body = response.json()
        q, qd = np.array(body["samples"]["q"]), np.array(body["samples"]["qd"])
        for waypoint in waypoints[1:-1]:
            at = np.argmin(np.linalg.norm(q - waypoint, axis=1))
            assert np.abs(qd[at]).max() <= 0.05, method
        ratio, kind = worst_ratio(body, robot_limits(client, "ur5"))
        assert ratio <= 1.005, (method, kind, ratio)


@pytest.mark.parametrize("dt", [0.01, 0.002])
def test_a_sample_on_a_stop_between_stretches_pairs_its_acceleration_with_the_next_stretch(client, dt):
    """A linear path stops at its middle waypoint after exactly 0.6 s of a trapezoid: the
    sample at t = 0.6 s (``np.arange``'s, a rounding short of the stop) paired the first
    stretch's deceleration with the second stretch's direction, 1.5 times the acceleration
    limit, and the answer was a 422."""
    waypoints = [[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [0.8, -1.0, 1.4, -0.5, 0.9, 0.3], [2.0, -1.3, 1.2, 0.2, 0.6, 1.2]]
    response = client.post("/v1/trajectories", json={
        "robot": "ur5", "path": {"kind": "waypoints", "interpolation": "linear", "waypoints": waypoints},
        "timing": {"method": "trapezoidal"}, "output": {"dt": dt},
    })
    assert response.status_code == 200, response.text
    body = response.json()
    t = np.array(body["samples"]["t"])
    assert np.min(np.abs(t - 0.6)) < 1e-12  # a sample on the stop
    ratio, kind = worst_ratio(body, robot_limits(client, "ur5"))
    assert ratio <= 1.005, (kind, ratio)


@pytest.mark.parametrize(
    "method", ["phase_plane", "toppra", "min_cost", "cubic", "quintic", "trapezoidal", "cycloidal", "ruckig", "jerk_limited"]
)
def test_a_one_joint_arm_is_planned_by_every_method(client, uploaded, method):
    constraints = ["velocity", "acceleration"] if method == "ruckig" else list(KINDS)
    body = {
        "robot": uploaded["pendulum_1r"],
        "path": {"kind": "waypoints", "waypoints": [[-0.5], [1.0]]},
        "timing": {"method": method, "constraints": constraints},
        "output": {"dt": 1e-3},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    ratio, kind = worst_ratio(response.json(), robot_limits(client, uploaded["pendulum_1r"]))
    assert ratio <= 1.005, (kind, ratio)


@pytest.mark.parametrize("interpolation", ["via", "linear"])
def test_one_and_two_joint_arms_through_several_waypoints(client, uploaded, interpolation):
    for stem, waypoints in (("pendulum_1r", [[-0.5], [0.4], [1.0]]), ("lift_rp", [[0.1, -1.0], [0.5, 0.0], [0.3, 1.2]])):
        response = plan(client, uploaded[stem], waypoints, "quintic", interpolation)
        assert response.status_code == 200, response.text
        ratio, kind = worst_ratio(response.json(), robot_limits(client, uploaded[stem]))
        assert ratio <= 1.005, (stem, kind, ratio)


def test_a_duration_too_short_for_the_limits_is_refused_with_where_and_which(client):
    waypoints = [[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [1.0, -0.8, 1.4, -0.5, 0.9, 0.3]]
    shortest = plan(client, "ur5", waypoints, "quintic").json()["duration"]
    response = plan(client, "ur5", waypoints, "quintic", duration=0.8 * shortest)
    assert response.status_code == 422, response.text
    problem = response.json()
    assert problem["limit"] in KINDS and problem["joint"] and 0.0 <= problem["s"] <= 1.0
    assert problem["limit"] in problem["detail"] and problem["joint"] in problem["detail"]


def test_a_recorded_path_that_stands_still_drops_its_repeated_waypoints(client):
    still = [0.0, -1.2, 1.0, 0.0, 0.5, 0.0]
    waypoints = [still, still, still, [0.5, -1.0, 1.2, -0.2, 0.6, 0.1], [0.5, -1.0, 1.2, -0.2, 0.6, 0.1], [1.0, -0.8, 1.4, -0.5, 0.9, 0.3]]
    for method in ("phase_plane", "ruckig"):
        chosen = waypoints if method == "phase_plane" else [still, still, waypoints[-1]]
        response = plan(client, "ur5", chosen, method, **({"constraints": ["velocity", "acceleration"]} if method == "ruckig" else {}))
        assert response.status_code == 200, response.text
        assert any(" dropped" in warning for warning in response.json()["warnings"])


def test_a_limit_not_asked_for_that_the_answer_exceeds_is_said():
    """Torque is not among the constraints, and its limit (1e-3 N m) is far below what the
    motion needs: the answer holds what was asked and says which joint's torque exceeds its
    limit, by how much, and how to hold it."""
    arm = robots.load("ur5")
    limits = LimitRequest(kinds=("velocity", "acceleration"), overrides={"torque": [1e-3] * 6})
    path = WaypointPath(np.array(UR5_WAYPOINTS[:2]))
    result = plan_library(build_problem(arm, path, TIMING_METHODS["phase_plane"], limits=limits, sampling=Sampling(0.05)))
    worst = int(np.argmax(result.peak_utilization["torque"]))
    (note,) = [w for w in result.warnings if "not asked for" in w]
    assert f"torque of joint {arm.joint_names[worst]!r}" in note
    assert f"{result.peak_utilization['torque'][worst]:.4g} times its limit" in note
    assert "add 'torque' to the constraints" in note
    asked = plan_library(build_problem(
        arm, WaypointPath(np.array(UR5_WAYPOINTS[:2])), TIMING_METHODS["phase_plane"],
        limits=LimitRequest(kinds=("velocity", "acceleration")), sampling=Sampling(0.05),
    ))
    assert not [w for w in asked.warnings if "not asked for" in w]


@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
def test_an_arm_with_coulomb_friction_is_timed_under_torque_limits_alone(client, method):
    """z1's joints have Coulomb friction F (1-2 N m). A torque-bound motion brakes at the limit
    to its end, where the friction (opposing the motion, F sign(q')) helps: the planning holds
    it so. The checks took the torque at the end, at rest, with sign(qd) = 0 and found it F
    (3.33 %) over the limit; every z1 path under torque limits alone was refused, with advice
    (more grid points, a lower scale) that changed nothing. At rest the friction now opposes
    the path's tangent, as the planning held it; the answer's torques are those of pinocchio's
    RNEA plus that friction, computed here, and within the limits."""
    import pinocchio as pin

    body = {
        "robot": "z1", "path": {"waypoints": [[0, 1.0, -1.0, 0, 0, 0], [0.5, 1.2, -1.2, 0.2, 0.2, 0.2]]},
        "timing": {"method": method, "constraints": ["torque"]}, "output": {"dt": 0.001},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    samples = response.json()["samples"]
    q, qd, qdd, tau = (np.array(samples[key]) for key in ("q", "qd", "qdd", "tau"))
    arm = robots.load("z1")
    model, data = arm.model, arm.model.createData()
    tangent = np.sign(np.subtract(*body["path"]["waypoints"][::-1]))  # a straight joint line's q'
    expected = np.array([
        pin.rnea(model, data, arm.configuration(row[None])[0], v, a) + model.damping * v
        + model.friction * np.where(v != 0.0, np.sign(v), tangent)
        for row, v, a in zip(q, qd, qdd, strict=True)
    ])
    np.testing.assert_allclose(tau, expected, atol=1e-9)
    assert np.abs(tau / arm.limits.torque).max() <= 1.003
