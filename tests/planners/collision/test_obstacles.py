"""Obstacles and clearance on given paths: capsule distances against coal's, capsules that
contain the collision meshes, and the HTTP answers (422 naming link, obstacle and s; the
closest approach of a clear path)."""

from __future__ import annotations

import re

import coal
import numpy as np
import pinocchio as pin
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners.collision import BoxObstacle, CapsuleObstacle, SphereObstacle
from toptraj.planners.collision.distance import capsule_distance
from toptraj.robots.collision import robot_capsules, world_capsules

RNG = np.random.default_rng(7)


def _coal_capsule(a, b, radius):
    """coal's capsule (along its z axis, centered) placed on the segment a-b."""
    axis = b - a
    length = float(np.linalg.norm(axis))
    z = axis / length
    x = np.cross(z, [1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.cross(z, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    rotation = np.column_stack([x, np.cross(z, x), z])
    return coal.Capsule(radius, length), coal.Transform3s(rotation, (a + b) / 2.0)


def _coal_distance(shape1, tf1, shape2, tf2) -> float:
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    return coal.distance(shape1, tf1, shape2, tf2, request, result)


def _random_obstacle(kind):
    if kind == "sphere":
        return SphereObstacle(RNG.uniform(-1, 1, 3), RNG.uniform(0.05, 0.3))
    if kind == "box":
        q = RNG.normal(size=4)
        return BoxObstacle(RNG.uniform(-1, 1, 3), RNG.uniform(0.05, 0.6, 3), q / np.linalg.norm(q))
    return CapsuleObstacle(RNG.uniform(-1, 1, 3), RNG.uniform(-1, 1, 3), RNG.uniform(0.02, 0.2))


def _coal_obstacle(obstacle):
    if isinstance(obstacle, SphereObstacle):
        return coal.Sphere(obstacle.radius), coal.Transform3s(np.eye(3), obstacle.center)
    if isinstance(obstacle, BoxObstacle):
        return coal.Box(*obstacle.size), coal.Transform3s(obstacle.rotation, obstacle.center)
    return _coal_capsule(obstacle.a, obstacle.b, obstacle.radius)


@pytest.mark.parametrize("kind", ["sphere", "box", "capsule"])
def test_capsule_distances_agree_with_coal(kind):
    checked = 0
    for _ in range(150):
        a, b, radius = RNG.uniform(-1, 1, 3), RNG.uniform(-1, 1, 3), RNG.uniform(0.01, 0.1)
        obstacle = _random_obstacle(kind)
        expected = _coal_distance(*_coal_capsule(a, b, radius), *_coal_obstacle(obstacle))
        if expected <= 0.0:
            continue  # penetration depth is not a distance; only the sign matters there
        ours = float(capsule_distance(a[None], b[None], np.array([radius]), obstacle)[0])
        assert ours == pytest.approx(expected, abs=1e-6)
        checked += 1
    assert checked > 40


def test_the_link_capsules_contain_ur5s_collision_meshes():
    """Conservative: a capsule is never farther from a sphere than the mesh it wraps (coal's
    mesh-to-sphere distance)."""
    robot = robots.load("ur5")
    from toptraj.robots.catalog import example_urdf_path

    path = example_urdf_path("ur5")
    model = pin.buildModelFromUrdf(path)
    geometry = pin.buildGeomFromUrdf(model, path, pin.COLLISION, package_dirs=[path.split("/example-robot-data/")[0]])
    capsules = {c.name: c for c in robot_capsules(robot)}
    data = model.createData()
    q = pin.neutral(model)
    pin.forwardKinematics(model, data, q)
    a, b = world_capsules(robot.model, robot.data, list(capsules.values()), q[None])
    by_name = {name: k for k, name in enumerate(capsules)}
    for item in geometry.geometryObjects:
        if not isinstance(item.geometry, coal.BVHModelBase):
            continue
        placement = data.oMi[item.parentJoint] * item.placement
        for _ in range(10):
            sphere = SphereObstacle(placement.translation + RNG.uniform(-0.6, 0.6, 3), 0.05)
            mesh = _coal_distance(item.geometry, coal.Transform3s(placement.rotation, placement.translation),
                                  coal.Sphere(0.05), coal.Transform3s(np.eye(3), sphere.center))
            k = by_name[item.name]
            ours = float(capsule_distance(a[0, k][None], b[0, k][None], np.array([capsules[item.name].radius]), sphere)[0])
            assert ours <= mesh + 1e-9


PATH = {"waypoints": UR5_WAYPOINTS}


def test_a_path_through_an_obstacle_is_a_422_naming_link_obstacle_and_s(client):
    sphere = {"kind": "sphere", "center": [0.5, 0.5, 0.5], "radius": 0.1}
    far = {"kind": "sphere", "center": [5.0, 5.0, 5.0], "radius": 0.1}
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [far, sphere]}})
    assert response.status_code == 422, response.text
    problem = response.json()
    assert problem["obstacle"] == 1 and problem["link"] in {c.link for c in robot_capsules(robots.load("ur5"))}  # the URDF's names
    assert 0.0 < problem["s"] < 1.0 and "path.obstacles[1]" in problem["detail"]


def test_a_clear_path_reports_its_closest_approach(client):
    box = {"kind": "box", "center": [0.6, 0.0, 0.2], "size": [0.2, 0.2, 0.2]}
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [box], "clearance": 0.02}})
    assert response.status_code == 200, response.text[:300]
    body = response.json()
    found = body["min_clearance"]
    assert found["obstacle"] == 0 and found["distance"] >= 0.02
    # coal, at every returned sample: never closer than reported (the check is denser), and close to it
    nearest = _coal_nearest(np.array(body["samples"]["q"]), BoxObstacle(np.array(box["center"]), np.array(box["size"])))
    assert found["distance"] - 1e-6 <= nearest <= found["distance"] + 0.01


def _coal_nearest(q: np.ndarray, obstacle) -> float:
    """The smallest distance (m), by coal, between ur5's link capsules at the rows of ``q`` and
    ``obstacle``."""
    robot = robots.load("ur5")
    capsules = robot_capsules(robot)
    a, b = world_capsules(robot.model, robot.data, capsules, robot.configuration(q))
    shape, placement = _coal_obstacle(obstacle)
    return min(
        _coal_distance(*_coal_capsule(a[i, k], b[i, k], capsules[k].radius), shape, placement)
        for i in range(len(q))
        for k in range(len(capsules))
        if np.linalg.norm(b[i, k] - a[i, k]) > 1e-9
    )


def test_a_lower_clearance_lets_a_close_path_through(client):
    """The sphere the default clearance (0.01 m) refuses: with clearance 0 the path is served,
    its closest approach is reported between 0 and 0.01 m (it grazes the ball), and coal finds
    every returned sample apart from the ball (it never touches), no closer than reported."""
    sphere = {"kind": "sphere", "center": [0.5, 0.5, 0.5], "radius": 0.1}
    refused = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [sphere]}})
    assert refused.status_code == 422, refused.text[:300]
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [sphere], "clearance": 0.0}})
    assert response.status_code == 200, response.text[:300]
    found = response.json()["min_clearance"]
    assert found["obstacle"] == 0 and 0.0 < found["distance"] < 0.01
    nearest = _coal_nearest(np.array(response.json()["samples"]["q"]), SphereObstacle(np.array(sphere["center"]), sphere["radius"]))
    assert found["distance"] - 1e-6 <= nearest <= found["distance"] + 0.01


def test_the_advice_of_a_close_path_is_the_clearance_that_lets_it_through(client):
    sphere = {"kind": "sphere", "center": [0.5, 0.5, 0.5], "radius": 0.1}
    refused = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [sphere]}})
    detail = refused.json()["detail"]
    advised = re.search(r"move the waypoints away from the obstacle or lower path\.clearance to (\S+) m$", detail)
    assert advised, detail
    followed = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [sphere], "clearance": float(advised.group(1))}})
    assert followed.status_code == 200, followed.text[:300]
    # Inside the ball, no clearance lets it through: only moving the waypoints is advised.
    inside = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [{**sphere, "radius": 0.3}], "clearance": 0.0}})
    assert inside.status_code == 422, inside.text[:300]
    assert re.search(
        r"move the waypoints away from the obstacle \(near s = \S+ the path touches an obstacle, or comes within about "
        r"half a millimetre of one\)$", inside.json()["detail"]), inside.json()["detail"]


def test_an_obstacle_on_a_link_no_joint_moves_advises_moving_it_or_the_robot(client):
    floor = {"kind": "box", "center": [0.0, 0.0, -0.05], "size": [2.0, 2.0, 0.2]}
    refused = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [floor]}})
    assert refused.status_code == 422 and refused.json()["link"] == "base_link", refused.text[:300]
    assert refused.json()["detail"].endswith(
        "no joint moves that link: move path.obstacles[0] away from it, or the robot by its mounting"
    ), refused.json()["detail"]
    lowered = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [{**floor, "center": [0.0, 0.0, -0.5]}]}})
    assert lowered.status_code == 200, lowered.text[:300]
    # near the base, not inside: a lower clearance is advised too, and following it plans the path
    near = {**floor, "center": [0.0, 0.0, -0.2]}
    close = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [near], "clearance": 0.2}})
    assert close.status_code == 422 and close.json()["link"] == "base_link", close.text[:300]
    advised = re.search(r"or the robot by its mounting, or lower path\.clearance to ([\d.]+) m$", close.json()["detail"])
    assert advised, close.json()["detail"]
    followed = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [near], "clearance": float(advised.group(1))}})
    assert followed.status_code == 200, followed.text[:300]


def test_the_planar_paper_arm_uses_link_capsules(client):
    """geering_2r's links are capsules of radius 0.03 m along l1 = 0.4 m and l2 = 0.25 m: a ball
    of radius 0.05 m on the hand's straight path at the line's middle."""
    path = {"waypoints": [[0.0, 0.0], [0.76, 0.0]], "obstacles": [{"kind": "sphere", "center": [0.65 * np.cos(0.38), 0.65 * np.sin(0.38), 0.0], "radius": 0.05}]}
    response = client.post("/v1/trajectories", json={"robot": "geering_2r", "path": path, "timing": {"constraints": ["torque"]}})
    assert response.status_code == 422 and response.json()["obstacle"] == 0
    # 0.65 + 0.03 + 0.05 + clearance from the shoulder, just out of reach: clear
    reach = 0.65 + 0.03 + 0.05 + 0.01 + 1e-3
    path["obstacles"][0]["center"] = [reach * np.cos(0.38), reach * np.sin(0.38), 0.0]
    response = client.post("/v1/trajectories", json={"robot": "geering_2r", "path": path, "timing": {"constraints": ["torque"]}})
    assert response.status_code == 200, response.text[:300]
    assert response.json()["min_clearance"]["distance"] == pytest.approx(0.011, abs=1e-6)


def test_obstacles_on_a_free_path_are_refused(client):
    body = {"robot": "geering_2r", "path": {"kind": "free", "start": [0, 0], "goal": [0.76, 0],
            "obstacles": [{"kind": "sphere", "center": [0.5, 0.2, 0], "radius": 0.05}]}, "timing": {"method": "collocation", "constraints": ["torque"]}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422 and "obstacles" in response.text


def _tool_points(robot, q: np.ndarray) -> np.ndarray:
    """The end effector's position (m) at every row of ``q``, by Pinocchio's forward kinematics."""
    frame = robot.frame_id(robot.end_effector)
    points = []
    for configuration in robot.configuration(q):
        pin.framesForwardKinematics(robot.model, robot.data, configuration)
        points.append(robot.data.oMf[frame].translation.copy())
    return np.array(points)


def test_obstacles_on_a_cartesian_line(client):
    """The lecture arm's tool on its straight line (the Cartesian example): a ball the tool
    passes through is a 422 naming it; moved 0.1 m off the line, the motion goes by it, and the
    reported clearance lies between the requested one and the tool point's own distance to the
    ball (the last link's capsule holds the tool point)."""
    body = {
        "robot": "lecture_3r",
        "path": {"kind": "cartesian", "start": [0.982793723247329, 0.474628419388735, 1.8266655408265058],
                 "positions": [[0.2286, 0.1524, 0.254], [0.0762, 0.127, 0.2032]]},
        "timing": {"method": "quintic", "constraints": ["velocity", "acceleration", "torque"]},
    }
    line = np.array(body["path"]["positions"])
    middle = line.mean(axis=0)
    ball = {"kind": "sphere", "center": middle.tolist(), "radius": 0.02}
    response = client.post("/v1/trajectories", json={**body, "path": {**body["path"], "obstacles": [ball]}})
    assert response.status_code == 422, response.text
    problem = response.json()
    assert problem["obstacle"] == 0 and "path.obstacles[0]" in problem["detail"] and 0.0 <= problem["s"] <= 1.0
    direction = np.diff(line, axis=0)[0] / np.linalg.norm(np.diff(line, axis=0)[0])
    aside = np.cross(direction, [0.0, 0.0, 1.0])
    aside /= np.linalg.norm(aside)
    ball["center"] = (middle + 0.1 * aside).tolist()
    response = client.post("/v1/trajectories", json={**body, "path": {**body["path"], "obstacles": [ball], "clearance": 0.01}})
    assert response.status_code == 200, response.text[:300]
    found = response.json()["min_clearance"]
    tips = _tool_points(robots.load("lecture_3r"), np.array(response.json()["samples"]["q"]))
    tip_distance = float(np.min(np.linalg.norm(tips - np.array(ball["center"]), axis=1))) - ball["radius"]
    assert found["obstacle"] == 0 and 0.01 <= found["distance"] <= tip_distance + 1e-9


@pytest.mark.parametrize("orientation, norm", [([0.0, 0.0, 0.0, 0.0], "0"), ([0.0, 0.0, 1e-30, 0.0], "1e-30"),
                                               ([0.0, 0.0, 0.0, 0.5], "0.5"), ([0.0, 0.0, 1.0, 1.0], "1.41421")])
def test_a_box_orientation_that_is_no_unit_quaternion_is_named(client, orientation, norm):
    box = {"kind": "box", "center": [0.6, 0.0, 0.2], "size": [0.2, 0.2, 0.2], "orientation": orientation}
    sphere = {"kind": "sphere", "center": [0.0, 0.0, 2.0], "radius": 0.1}
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [sphere, box]}})
    assert response.status_code == 422, response.text
    assert response.json()["detail"].startswith(f"path.obstacles[1].orientation has norm {norm}; a box's orientation is a unit quaternion")


def test_obstacles_far_beyond_the_arms_reach_are_noted(client):
    """A sphere given in millimetres (500, 200, 300 for 0.5, 0.2, 0.3 m) is 565 m from ur5, whose
    reach is under a metre: the answer says the obstacles constrain nothing and are in metres; one
    within reach is not noted."""
    far = {"kind": "sphere", "center": [500.0, 200.0, 300.0], "radius": 50.0}
    answer = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [far]}}).json()
    [noted] = [warning for warning in answer["warnings"] if "path.obstacles" in warning]
    assert noted.startswith(f"the obstacles of path.obstacles stay at least {answer['min_clearance']['distance']:.4g} m from the arm")
    assert "a position in millimetres is a thousand times too far" in noted
    near = {"kind": "sphere", "center": [0.5, 0.5, 0.9], "radius": 0.05}
    answer = client.post("/v1/trajectories", json={"robot": "ur5", "path": {**PATH, "obstacles": [near]}}).json()
    assert not any("path.obstacles" in warning for warning in answer["warnings"]), answer
