"""A prismatic joint's effort is a force: the errors about holding a path still speak of it in N,
as its limit is given, and a revolute joint's in N m (a lift carrying 22 kg needs 22 x 9.81 =
215.8 N against its URDF effort of 100 N)."""

from __future__ import annotations

import re

import pytest
from fastapi.testclient import TestClient

from toptraj.service.app import create_app
from toptraj.service.settings import Settings

LIFT = """<robot name="slider">
  <link name="base"/>
  <link name="carriage"><inertial><mass value="20"/><origin xyz="0 0 0"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="2"/><origin xyz="0.3 0 0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="lift" type="prismatic"><parent link="base"/><child link="carriage"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="1" effort="100" velocity="1"/></joint>
  <joint name="turn" type="revolute"><parent link="carriage"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with TestClient(create_app(Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("units")))) as test_client:
        assert test_client.post("/v1/robots", json={"name": "slider", "urdf": LIFT}).status_code == 201
        yield test_client


def test_holding_a_prismatic_joint_still_is_worded_in_newtons(client):
    response = client.post("/v1/trajectories", json={"robot": "slider", "path": {"waypoints": [[0.0, 0.0], [0.5, 1.0]]},
                                                     "timing": {"constraints": ["torque"]}})
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    weight = 22.0 * 9.81
    assert f"holding still at s = 0.0000 needs {weight:.4g} N on joint 'lift', above its limit of 100 N;" in detail, detail
    assert "timing.limits.torque of 217 N on joint 'lift'" in detail and "N m" not in detail


def test_a_cell_arm_that_cannot_hold_its_path_names_the_unit_and_a_remedy_it_can_follow(client):
    arm = {"robot": "slider", "waypoints": [[0.0, 0.0], [0.5, 1.0]], "torque_scale": 1.0}
    cell = {"arms": [arm, {**arm, "base": {"position": [2.0, 0.0, 0.0]}}], "constraints": ["velocity", "torque"]}
    response = client.post("/v1/cells", json=cell)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert f"needs {22.0 * 9.81:.4g} N on joint 'lift', above its torque limit of 100 N (gravity)" in detail, detail
    assert "raise the limit" not in detail and detail.endswith("no timing holds it; move arms[0].waypoints there to where the arm holds itself with less torque")


def test_the_clearance_of_a_sliding_arm_is_checked_at_its_slide(client):
    """The slider's reach bound is 0.03 m, yet its lift moves every point of the arm by the whole
    slide: a sphere 1 mm from the carriage's path at mid-lift, radius 0.5 mm, under a clearance of
    1 mm is 0.99 mm from the arm there by an independent computation (the carriage's capsule axis is
    the lift's axis, of radius 0.03 m), so the path is refused, not served with a clearance of 1.09
    mm found between too sparse samples."""
    from toptraj import robots
    from toptraj.robots.collision import robot_capsules

    carriage = next(c for c in robot_capsules(robots.load("slider")) if c.link == "carriage")
    center = [carriage.radius + 0.0015 - 0.00001, 0.0, 0.5025]
    sphere = {"kind": "sphere", "center": center, "radius": 0.0005}
    body = {"robot": "slider", "path": {"waypoints": [[0.0, 0.0], [1.0, 0.0]], "obstacles": [sphere], "clearance": 0.001},
            "timing": {"constraints": ["velocity", "acceleration"]}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422 and response.json()["link"] == "carriage", response.text[:300]


TURN_SLIDE = """<robot name="turn_slide">
  <link name="base"/>
  <link name="boom"><inertial><mass value="5"/><origin xyz="0 0 0"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/><origin xyz="0 0 0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="boom"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="boom"/><child link="tip"/><origin xyz="0.1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="3" effort="100" velocity="1"/></joint>
</robot>"""


def test_the_motion_bound_counts_what_a_slide_can_carry_out(client):
    """A turn before a 3 m slide: at full slide the tip is 3.1 m from the turn's axis, and the
    bound on how far a turn moves any point (per radian) must be at least that, not the 0.1 m of
    the joints' placement at zero."""
    from toptraj import robots
    from toptraj.planners.collision.clearance import _reach, sliding_travel

    assert client.post("/v1/robots", json={"name": "turn_slide", "urdf": TURN_SLIDE}).status_code == 201
    robot = robots.load("turn_slide")
    assert sliding_travel(robot) == 3.0 and _reach(robot) >= 3.1


def test_a_cell_arm_is_told_to_raise_its_torque_scale_only_where_that_holds_it(client):
    """The slider's lift needs 215.8 N, above its own 100 N: under a torque scale of 0.5, raising
    the scale cannot hold it and is not advised, only the waypoints. A ur5 holding its upper arm
    out needs 59.2 N m of its 150: under a scale of 0.1 the scale that holds it is advised, and
    following the advice plans the cell."""
    arm = {"robot": "slider", "waypoints": [[0.0, 0.0], [0.5, 1.0]], "torque_scale": 0.5}
    cell = {"arms": [arm, {**arm, "base": {"position": [2.0, 0.0, 0.0]}}], "constraints": ["velocity", "torque"]}
    detail = client.post("/v1/cells", json=cell).json()["detail"]
    assert "torque_scale" not in detail and detail.endswith("move arms[0].waypoints there to where the arm holds itself with less torque")
    lift = [[0.0, -1.57, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]]
    ur5 = {"robot": "ur5", "waypoints": lift, "torque_scale": 0.1}
    cell = {"arms": [ur5, {**ur5, "base": {"position": [3.0, 0.0, 0.0]}}], "constraints": ["velocity", "acceleration", "torque"]}
    detail = client.post("/v1/cells", json=cell).json()["detail"]
    advised = re.search(r"raise arms\[0\]\.torque_scale to ([\d.]+) or more \(at most 1\)", detail)
    assert advised and 59.17 / 150 < float(advised.group(1)) <= 0.4, detail
    followed = [{**arm, "torque_scale": float(advised.group(1))} for arm in cell["arms"]]
    assert client.post("/v1/cells", json=cell | {"arms": followed}).status_code == 200
