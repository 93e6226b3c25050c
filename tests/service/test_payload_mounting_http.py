"""POST /v1/trajectories with a ``payload`` and a ``mounting``: the answer's torques against
Pinocchio models built independently, limits that bind because of the payload, and world-frame
Cartesian lines from a moved base."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from tests.conftest import UR5_WAYPOINTS
from tests.robots.test_equipment import COM, INERTIA, MASS, _ur5_with_load_link
from toptraj import robots
from toptraj.robots import equipment
from toptraj.robots.catalog import BUNDLED

#: ur5's torque limits halved (75 N m on the big joints), so that a 2 kg tool makes them bind.
HALF_TORQUE = {"limits": {"torque_scale": 0.5}}


def _plan(client, **fields):
    body = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "timing": HALF_TORQUE, "output": {"dt": 0.002}, **fields}
    response = client.post("/v1/trajectories", json=body)
    return response.status_code, response.json()


def _samples(answer):
    samples = answer["samples"]
    return (np.array(samples[key]) for key in ("q", "qd", "qdd", "tau"))


def _rnea(model: pin.Model, q, qd, qdd) -> np.ndarray:
    data = model.createData()
    return np.array([pin.rnea(model, data, *state) for state in zip(q, qd, qdd)])


def test_answer_torques_are_the_rnea_with_the_payload_as_a_link(client):
    inertia = [INERTIA[0, 0], INERTIA[1, 1], INERTIA[2, 2], INERTIA[0, 1], INERTIA[0, 2], INERTIA[1, 2]]
    code, answer = _plan(client, timing={}, payload={"mass": MASS, "center_of_mass": list(COM), "inertia": inertia})
    assert code == 200, answer
    q, qd, qdd, tau = _samples(answer)
    assert np.abs(tau - _rnea(_ur5_with_load_link(), q, qd, qdd)).max() <= 1e-9


def test_a_payload_that_makes_a_torque_limit_bind_lengthens_the_motion(client):
    code, bare = _plan(client)
    assert code == 200, bare
    code, loaded = _plan(client, payload={"mass": 2.0, "center_of_mass": [0.0, 0.0, 0.1]})
    assert code == 200, loaded
    assert max(bare["peak_utilization"]["torque"]) < 0.97  # the bare arm is not torque-bound
    assert 0.99 <= max(loaded["peak_utilization"]["torque"]) <= 1.005  # the loaded one is, within 0.5 %
    assert loaded["duration"] > 1.2 * bare["duration"]


def test_a_payload_too_heavy_for_the_path_is_a_422_naming_the_joint_and_s(client):
    code, problem = _plan(
        client, payload={"mass": 40.0, "center_of_mass": [0.0, 0.0, 0.1]}, path={"waypoints": [[0, -1.2, 1.0, 0, 0, 0], [0.5, -0.3, 0.2, 0, 0, 0]]}
    )
    assert code == 422, problem
    assert problem["limit"] == "torque" and problem["joint"] == "shoulder_lift_joint" and 0.0 <= problem["s"] <= 1.0
    assert "shoulder_lift_joint" in problem["detail"] and "s = " in problem["detail"]
    assert "payload of 40 kg at tool0" in problem["detail"] and "payload.mass" in problem["detail"]


def test_a_ceiling_mounted_arm_feels_the_floor_arms_gravity_reversed(client):
    code, answer = _plan(client, mounting={"position": [0.0, 0.3, 2.5], "orientation": [1.0, 0.0, 0.0, 0.0]})
    assert code == 200, answer
    q, qd, qdd, tau = _samples(answer)
    floor_reversed = robots.load("ur5").model.copy()
    floor_reversed.gravity = pin.Motion(np.array([0.0, 0.0, 9.81]), np.zeros(3))
    assert np.abs(tau - _rnea(floor_reversed, q, qd, qdd)).max() <= 1e-9


def test_the_answer_echoes_the_payload_and_mounting_it_applied_with_units(client):
    code, bare = _plan(client, timing={})
    assert code == 200, bare
    assert bare["payload"] is None and bare["mounting"] is None
    inertia = [0.02, 0.025, 0.03, 0.001, 0.0, 0.002]
    code, answer = _plan(
        client, timing={}, payload={"mass": 2.0, "center_of_mass": [0.0, 0.01, 0.1], "inertia": inertia},
        mounting={"position": [0.0, 0.3, 2.5], "orientation": [1.0, 0.0, 0.0, 0.0]},
    )
    assert code == 200, answer
    assert answer["payload"] == {
        "mass": 2.0,
        "center_of_mass": [0.0, 0.01, 0.1],
        "inertia": [[0.02, 0.001, 0.0], [0.001, 0.025, 0.002], [0.0, 0.002, 0.03]],
        "frame": "tool0",
        "radius": 0.0,
        "units": {"mass": "kg", "center_of_mass": "m", "inertia": "kg m^2", "radius": "m"},
    }
    mounting = answer["mounting"]
    assert mounting["position"] == [0.0, 0.3, 2.5]
    # the quaternion [1, 0, 0, 0]: half a turn about x
    np.testing.assert_allclose(mounting["rotation"], [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]], atol=1e-12)
    np.testing.assert_allclose(mounting["gravity"], [0.0, 0.0, -9.81], atol=1e-12)  # the world's, not the base's
    assert mounting["units"]["position"] == "m" and mounting["units"]["gravity"] == "m/s^2"
    code, walled = _plan(client, timing={}, mounting={"gravity": [0.0, -9.81, 0.0]})
    assert code == 200, walled
    assert walled["mounting"]["gravity"] == [0.0, -9.81, 0.0] and walled["payload"] is None


@pytest.mark.parametrize(
    ("mounting", "field", "words"),
    [
        ({"rotation": [[1, 0, 0], [0, 1, 0], [0, 0.5, 1]]}, "mounting.rotation", "R^T R differs from the identity by 0.5"),
        ({"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, -1]]}, "mounting.rotation", "a reflection"),
        ({"orientation": [0.0, 0.0, 0.0, 2.0]}, "mounting.orientation", "norm 2: not a rotation"),
        ({"orientation": [0.0, 0.0, 0.0, 1.0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}, "mounting", "not both"),
        ({"position": [0.0, 0.0, 1e7]}, "mounting.position[2]", "[-1000, 1000] m"),
    ],
)
def test_a_base_pose_that_is_not_a_rotation_is_a_422_naming_the_field(client, mounting, field, words):
    code, problem = _plan(client, mounting=mounting)
    assert code == 422, problem
    assert [error["field"] for error in problem["errors"]] == [field] and words in problem["detail"], problem


@pytest.mark.parametrize(
    ("payload", "field"),
    [
        ({"mass": 1e4}, "payload.mass"),
        ({"mass": 1.0, "inertia": [1.0, 1.0, 3.0, 0.0, 0.0, 0.0]}, "payload.inertia"),
        ({"mass": 1.0, "center_of_mass": [0.0, 0.0, 20.0]}, "payload.center_of_mass[2]"),
    ],
)
def test_an_unphysical_payload_is_a_422_naming_the_field(client, payload, field):
    code, problem = _plan(client, payload=payload)
    assert code == 422, problem
    assert [error["field"] for error in problem["errors"]] == [field]


def test_a_world_cartesian_line_from_a_moved_base_reaches_the_same_world_points(client):
    ur5 = robots.load("ur5")
    base = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, np.pi / 2), np.array([1.0, -0.5, 0.4]))
    start = [0.3, -1.4, 1.6, -1.8, -1.5, 0.2]
    pin.framesForwardKinematics(ur5.model, ur5.data, np.array(start))
    world_start = (base * ur5.data.oMf[ur5.frame_id("tool0")]).translation
    targets = [world_start + [0.15, 0.0, 0.0], world_start + [0.15, 0.1, -0.05]]
    code, answer = _plan(
        client,
        mounting={"position": base.translation.tolist(), "rotation": base.rotation.tolist()},
        path={"kind": "cartesian", "start": start, "positions": [target.tolist() for target in targets]},
    )
    assert code == 200, answer
    q = np.array(answer["samples"]["q"])
    world = np.array([(base * _tool(ur5, row)).translation for row in q])
    assert np.abs(world[-1] - targets[-1]).max() <= 1e-4
    corner = np.linalg.norm(world - targets[0], axis=1).min()
    assert corner <= 2e-3  # the polyline stops at its corner: a sample lies at it, within a step
    on_lines = [_distance_to_segment(world, world_start, targets[0]), _distance_to_segment(world, targets[0], targets[1])]
    assert np.minimum(*on_lines).max() <= 1e-4


def _tool(robot, q) -> pin.SE3:
    pin.framesForwardKinematics(robot.model, robot.data, q)
    return robot.data.oMf[robot.frame_id("tool0")].copy()


def _distance_to_segment(points, a, b) -> np.ndarray:
    along = np.clip((points - a) @ (b - a) / float((b - a) @ (b - a)), 0.0, 1.0)
    return np.linalg.norm(points - (a + along[:, None] * (b - a)), axis=1)


def test_an_uploads_default_payload_applies_unless_a_request_gives_its_own(client):
    from importlib import resources

    urdf = resources.files("toptraj.robots").joinpath("urdf/lecture_3r.urdf").read_text()
    default = {"mass": 1.5, "center_of_mass": [0.05, 0.0, 0.0], "radius": 0.04}
    created = client.post("/v1/robots", json={"name": "lecture_loaded", "urdf": urdf, "payload": default})
    assert created.status_code == 201, created.text
    described = client.get("/v1/robots/lecture_loaded").json()["payload"]
    assert described == {"mass": 1.5, "center_of_mass": [0.05, 0.0, 0.0], "inertia": [[0.0] * 3] * 3, "frame": "hand", "radius": 0.04}
    catalog = robots.load("lecture_3r")
    path = {"waypoints": [[0.0, 0.2, -0.3], [0.8, -0.4, 0.5]]}
    for payload, expected in ((None, default), ({"mass": 0.0}, None), ({"mass": 0.5}, {"mass": 0.5})):
        body = {"robot": "lecture_loaded", "path": path, "output": {"dt": 0.01}}
        if payload is not None:
            body["payload"] = payload
        response = client.post("/v1/trajectories", json=body)
        assert response.status_code == 200, response.text
        q, qd, qdd, tau = _samples(response.json())
        echoed = response.json()["payload"]
        if expected is None:
            assert echoed is None
        else:  # the stored default keeps its collision radius; a request's own payload replaces it
            assert (echoed["mass"], echoed["frame"], echoed["radius"]) == (expected["mass"], "hand", expected.get("radius", 0.0))
        carried = catalog if expected is None else equipment.equip(catalog, equipment.payload(**expected, frame=BUNDLED["lecture_3r"]))
        assert np.abs(tau - carried.inverse_dynamics(q, qd, qdd)).max() <= 1e-9


def test_obstacles_are_in_the_world_frame_of_a_moved_base(client):
    """A ball on the bare arm's tool path blocks it; with the base moved 2 m away the same ball
    is far off, and the ball moved with the base blocks the moved arm at the same s."""
    ur5 = robots.load("ur5")
    middle = _tool(ur5, np.array(UR5_WAYPOINTS[1])).translation
    base = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 2.0), np.array([2.0, 0.0, 0.0]))
    mounting = {"position": base.translation.tolist(), "rotation": base.rotation.tolist()}

    def plan_around(center, **fields):
        path = {"waypoints": UR5_WAYPOINTS, "obstacles": [{"kind": "sphere", "center": list(center), "radius": 0.05}]}
        return _plan(client, timing={}, path=path, **fields)

    code, bare = plan_around(middle)
    assert code == 422 and bare["obstacle"] == 0, bare
    code, answer = plan_around(middle, mounting=mounting)
    assert code == 200 and answer["min_clearance"]["distance"] > 0.5, answer
    code, moved = plan_around((base * pin.SE3(np.eye(3), middle)).translation, mounting=mounting)
    assert code == 422 and moved["link"] == bare["link"] and moved["s"] == pytest.approx(bare["s"], abs=1e-9), moved


def test_a_comparison_plans_every_method_with_the_payload(client):
    payload = {"mass": 2.0, "center_of_mass": [0.0, 0.0, 0.1]}
    code, alone = _plan(client, payload=payload)
    assert code == 200, alone
    body = {"robot": "ur5", "payload": payload, "path": {"waypoints": UR5_WAYPOINTS}, "methods": ["phase_plane"], "timing": HALF_TORQUE}
    response = client.post("/v1/trajectories/compare", json=body)
    assert response.status_code == 200, response.text
    assert response.json()["results"][0]["duration"] == pytest.approx(alone["duration"], rel=1e-12)


def test_a_tool_speed_limit_holds_in_the_world_whatever_the_base_pose(client):
    """A speed is the same in every frame: moving and turning the base changes none, so a motion
    bound by the tool's speed and the joints' accelerations (not by torques) lasts as long on a
    wall as on the floor, the tool at its limit in both."""
    timing = {"constraints": ["velocity", "acceleration"], "limits": {"tool_speed": 0.3}}
    code, floor = _plan(client, timing=timing)
    assert code == 200 and floor["peak_utilization"]["tool_speed"] == pytest.approx(1.0, abs=5e-3), floor
    wall = {"position": [0.5, 1.0, 1.5], "rotation": pin.rpy.rpyToMatrix(np.pi / 2, 0.0, 0.3).tolist()}
    code, mounted = _plan(client, timing=timing, mounting=wall)
    assert code == 200, mounted
    assert mounted["duration"] == pytest.approx(floor["duration"], rel=1e-9)
    assert mounted["peak_utilization"]["tool_speed"] == pytest.approx(floor["peak_utilization"]["tool_speed"], rel=1e-9)


def test_a_payload_on_a_frame_the_robot_lacks_is_a_422_listing_its_frames(client):
    code, problem = _plan(client, payload={"mass": 1.0, "frame": "gripper_tip"})
    assert code == 422, problem
    assert "'gripper_tip' is not a frame of ur5" in problem["detail"] and "'tool0'" in problem["detail"]


def test_the_skeleton_of_a_mounted_arm_is_placed_in_the_world(client):
    q = [UR5_WAYPOINTS[1], UR5_WAYPOINTS[2]]
    base = pin.SE3(pin.rpy.rpyToMatrix(np.pi, 0.0, 0.5), np.array([0.2, -0.4, 2.0]))
    bare = client.post("/v1/robots/ur5/skeleton", json={"q": q}).json()["positions"]
    mounting = {"position": base.translation.tolist(), "rotation": base.rotation.tolist()}
    moved = client.post("/v1/robots/ur5/skeleton", json={"q": q, "mounting": mounting}).json()["positions"]
    expected = np.array(bare) @ base.rotation.T + base.translation
    assert np.abs(np.array(moved) - expected).max() <= 1e-12


def test_a_payload_with_a_radius_is_kept_from_obstacles_like_a_link(client):
    # a small sphere 0.25 m beyond tool0 along its z axis at the second waypoint: clear of the arm
    robot = robots.load("ur5")
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(np.array([UR5_WAYPOINTS[1]]))[0])
    tool = data.oMf[robot.model.getFrameId("tool0")]
    center = tool.translation + 0.25 * tool.rotation[:, 2]
    path = {"waypoints": UR5_WAYPOINTS, "obstacles": [{"kind": "sphere", "center": center.tolist(), "radius": 0.03}]}
    code, answer = _plan(client, timing={}, path=path, payload={"mass": 1.0, "center_of_mass": [0.0, 0.0, 0.15]})
    assert code == 200, answer
    assert answer["min_clearance"]["distance"] > 0.03 and answer["min_clearance"]["link"] != "payload"
    # the payload a sphere of 0.1 m about its centre of mass, 0.15 m along tool0's z: it reaches 0.25 m
    code, problem = _plan(client, timing={}, path=path, payload={"mass": 1.0, "center_of_mass": [0.0, 0.0, 0.15], "radius": 0.1})
    assert code == 422, problem
    assert "payload" in problem["detail"] and "obstacles[0]" in problem["detail"]


@pytest.mark.parametrize(
    ("gravity", "refused", "words"),
    [
        ([0.0, 0.0, 9.81], False, "mounting.gravity [0, 0, 9.81] points up (+z in the world), and the torques follow it"),
        ([0.0, 0.0, -98.1], True, "mounting.gravity [0, 0, -98.1] has a magnitude of 98.1 m/s^2, and the torques follow it"),
    ],
)
def test_a_gravity_that_looks_mistyped_is_noted(client, gravity, refused, words):
    """The sign of g, or g in the wrong unit: the answer is right for the gravity given, and says
    that it is unusual (at ten times the Earth's, the arm cannot hold itself and the refusal says
    why); the Earth's gravity, or none, is not noted."""
    body = {"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}, "mounting": {"gravity": gravity}}
    answer = client.post("/v1/trajectories", json=body).json()
    if refused:
        assert answer["status"] == 422 and f"; {words}" in answer["detail"], answer
    else:
        assert any(warning.startswith(words) for warning in answer["warnings"]), answer
    for quiet in ([0.0, 0.0, -9.81], [0.0, 0.0, 0.0]):
        answer = client.post("/v1/trajectories", json=body | {"mounting": {"gravity": quiet}}).json()
        assert not any("mounting.gravity" in warning for warning in answer["warnings"]), answer["warnings"]
