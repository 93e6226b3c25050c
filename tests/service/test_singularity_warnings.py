"""A singularity warning says what to do, and an arm singular all along is not said to pass
through a singularity at t = 0 s."""

from __future__ import annotations

from tests.conftest import UR5_WAYPOINTS
from tests.paths import DATA


def _warnings(client, robot: str, waypoints) -> tuple[list[str], dict]:
    body = {"robot": robot, "path": {"kind": "waypoints", "waypoints": waypoints}, "timing": {"method": "phase_plane"}, "output": {"dt": 0.01}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    return response.json()["warnings"], response.json()["conditioning"]


def test_a_singularity_passed_through_comes_with_a_remedy(client):
    warnings, conditioning = _warnings(client, "ur5", UR5_WAYPOINTS)
    assert conditioning["kappa_max"] is None and conditioning["kappa_min"] is not None
    (note,) = [w for w in warnings if "singularity" in w]
    assert note.startswith("the arm passes through a singularity at t = 0 s")
    assert "move the path's waypoints near t = 0 s off that pose" in note


def test_an_arm_singular_all_along_names_no_instant(client):
    urdf = (DATA / "pendulum_1r.urdf").read_text()
    cut = urdf.index('  <joint name="tip_mount"')
    urdf = urdf[:cut] + "</robot>\n"  # its end effector, the link's origin, lies on the joint's axis
    response = client.post("/v1/robots", json={"name": "pendulum_on_axis", "urdf": urdf})
    assert response.status_code == 201, response.text
    warnings, conditioning = _warnings(client, response.json()["name"], [[0.0], [1.5]])
    assert conditioning["kappa_min"] is None and conditioning["kappa_max"] is None
    (note,) = [w for w in warnings if "singularity" in w]
    assert "at t =" not in note and "all along the motion" in note and "needs no change" in note


def test_a_free_path_is_told_to_move_its_start_or_goal_not_waypoints(client):
    """The Geering arm starts stretched out (a singular pose): its free motion has no waypoints."""
    body = {
        "robot": "geering_2r",
        "path": {"kind": "free", "start": [0.0, 0.0], "goal": [0.76, 0.0], "revolutions": True},
        "timing": {"method": "collocation", "constraints": ["torque"]},
        "output": {"dt": 0.01},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    (note,) = [w for w in response.json()["warnings"] if "singularity" in w]
    assert note.startswith("the arm passes through a singularity at t = 0 s")
    assert note.endswith("to avoid it at an end of the motion, move its start or goal off that pose (between them, the path is the planner's)")
