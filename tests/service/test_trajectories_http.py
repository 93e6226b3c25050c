"""POST /v1/trajectories end to end: the ur5 acceptance motion and the paper arms."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots

DT = 0.0005


@pytest.fixture(scope="module", params=["phase_plane", "toppra"])
def ur5_result(client, request):
    body = {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": "spline"},
        "timing": {"method": request.param, "constraints": ["velocity", "acceleration", "torque"]},
        "output": {"dt": DT},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    return response.json()


def _arrays(result):
    samples = result["samples"]
    return (np.array(samples[key]) for key in ("t", "q", "qd", "qdd", "tau"))


def test_ur5_starts_and_ends_at_rest_on_the_waypoints(ur5_result):
    t, q, qd, qdd, tau = _arrays(ur5_result)
    assert t[0] == 0.0 and t[-1] == pytest.approx(ur5_result["duration"], abs=1e-12)
    assert q[0] == pytest.approx(UR5_WAYPOINTS[0], abs=1e-12)
    assert q[-1] == pytest.approx(UR5_WAYPOINTS[-1], abs=1e-9)
    assert np.abs(qd[0]).max() <= 1e-12 and np.abs(qd[-1]).max() <= 1e-9
    speed = np.abs(qd).max()
    for waypoint in UR5_WAYPOINTS[1:-1]:
        assert np.min(np.linalg.norm(q - waypoint, axis=1)) <= 0.5 * DT * speed * np.sqrt(6)


def test_ur5_samples_are_consistent_and_tau_is_rnea(ur5_result):
    t, q, qd, qdd, tau = _arrays(ur5_result)
    # Velocities are the derivative of positions: a central difference is off by at most
    # dt / 2 times the jump of the (piecewise-smooth) acceleration within the two steps.
    differences = (q[2:] - q[:-2]) / (t[2:] - t[:-2])[:, None]
    assert np.abs(differences - qd[1:-1]).max() <= DT * np.abs(qdd).max()
    robot = robots.load("ur5")
    data = robot.model.createData()
    for k in range(0, len(t), 37):
        expected = pin.rnea(robot.model, data, q[k], qd[k], qdd[k])
        assert tau[k] == pytest.approx(expected, abs=1e-9)


def test_ur5_limits_hold_on_a_dense_resampling(ur5_result):
    """Every sample at dt = 0.5 ms within 0.5 % of every limit, and the answer is time-optimal
    in the sense that some limit binds."""
    t, q, qd, qdd, tau = _arrays(ur5_result)
    limits = robots.load("ur5").limits
    ratios = {
        "velocity": np.abs(qd).max(axis=0) / limits.velocity,
        "acceleration": np.abs(qdd).max(axis=0) / limits.acceleration,
        "torque": np.abs(tau).max(axis=0) / limits.torque,
    }
    for kind, ratio in ratios.items():
        assert ratio.max() <= 1.005, kind
        assert np.array(ur5_result["peak_utilization"][kind]).max() <= 1.005
        assert np.array(ur5_result["peak_utilization"][kind]) == pytest.approx(ratio, abs=5e-3)
    assert max(ratio.max() for ratio in ratios.values()) >= 0.995
    assert not [note for note in ur5_result["warnings"] if "limit" in note]
    assert ur5_result["conditioning"]["kappa_max"] is None  # the start has the wrist singular (q5 = 0)
    assert any(note.startswith("the arm passes through a singularity at t = 0 s: its Jacobian loses rank") for note in ur5_result["warnings"])


def test_ur5_phase_plane_stays_under_the_mvc(ur5_result):
    plane = ur5_result["phase_plane"]
    if ur5_result["method"] == "phase_plane":
        assert {point["kind"] for point in plane["switch_points"]} & {"tangent", "singular", "discontinuity"}
    sd, sd_max = np.array(plane["sd"]), np.array(plane["sd_max"], dtype=float)
    assert plane["s"][0] == 0.0 and plane["s"][-1] == 1.0
    assert sd[0] == 0.0 and sd[-1] == 0.0
    assert np.all(sd <= sd_max * (1 + 1e-6) + 1e-9)


@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
@pytest.mark.parametrize(
    "robot, waypoints",
    [
        ("geering_2r", [[0.0, 0.0], [0.76, 0.0]]),
        ("yamamoto_2r", np.radians([[45.0, -90.0], [-90.0, 0.0]]).tolist()),
    ],
)
def test_paper_arm_torque_limited_straight_line(client, robot, waypoints, method):
    body = {
        "robot": robot,
        "path": {"kind": "waypoints", "waypoints": waypoints},
        "timing": {"method": method, "constraints": ["torque"], "grid_points": 1000},
        "output": {"dt": 0.001},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    tau = np.array(result["samples"]["tau"])
    limit = robots.load(robot).limits.torque
    assert np.abs(tau).max(axis=0).max() / 1 <= 1.005 * limit.max()
    assert (np.abs(tau).max(axis=0) / limit).max() <= 1.005
    assert (np.abs(tau).max(axis=0) / limit).max() >= 0.995  # bang-bang: a torque saturates
    assert result["samples"]["q"][-1] == pytest.approx(waypoints[-1], abs=1e-9)


def test_request_models_are_frozen_and_share_their_defaults():
    """A request is read, never changed: its models are frozen, so the default sub-models
    (limits, boundary, cost, trapezoid) are hashable and every request shares them instead of
    validating a deep copy of each."""
    from pydantic import ValidationError

    from toptraj.service.schemas.trajectories import TrajectoryRequest

    body = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS[:2]}, "timing": {"method": "phase_plane"}}
    first, second = TrajectoryRequest.model_validate(body), TrajectoryRequest.model_validate(body)
    for name in ("limits", "boundary", "cost", "trapezoid"):
        assert getattr(first.timing, name) is getattr(second.timing, name), name
    with pytest.raises(ValidationError, match="frozen"):
        first.timing.limits.velocity_scale = 0.5
