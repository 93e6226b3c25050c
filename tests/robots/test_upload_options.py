"""Upload options: joints locked at a value, limits in MoveIt's joint_limits.yaml form, where
each limit comes from, and records stored before options existed."""

from __future__ import annotations

import sqlite3
import time
from pathlib import Path

import numpy as np
import pytest

from toptraj import robots
from toptraj.robots.catalog import example_urdf_path
from toptraj.robots.upload_options import InvalidUpload, upload_options

PANDA = Path(example_urdf_path("panda")).read_text()
UR5 = Path(example_urdf_path("ur5")).read_text()
FINGERS = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.02}
UR5_JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
UR5_LIMITS_YAML = "joint_limits:\n" + "".join(
    f"  {joint}:\n    has_acceleration_limits: true\n    max_acceleration: 2.0\n"
    f"    has_jerk_limits: true\n    max_jerk: {40.0 + k}\n" + (
        "    has_velocity_limits: true\n    max_velocity: 1.0\n" if joint == "shoulder_pan_joint" else
        "    has_velocity_limits: true\n    max_velocity: 99.0\n" if joint == "elbow_joint" else ""
    )
    for k, joint in enumerate(UR5_JOINTS)
) + "default_velocity_scaling_factor: 0.1\n"


def test_an_uploaded_panda_with_locked_fingers_plans_its_seven_joints(client):
    closed = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}
    response = client.post("/v1/robots", json={"name": "panda_arm", "urdf": PANDA, "locked_joints": closed})
    assert response.status_code == 201, response.text
    robot = response.json()
    assert robot["dof"] == 7 and len(robot["joint_names"]) == 7
    assert not any("finger" in name for name in robot["joint_names"])
    assert robot["locked_joints"] == closed
    assert any("mesh files are not loaded" in note for note in robot["notes"])
    assert any("panda_finger_joint2 = 0" in note for note in robot["notes"])
    # The catalog's panda locks its fingers at 0 too: same joints, same torques.
    catalog = robots.load("panda")
    assert robot["joint_names"] == list(catalog.joint_names)
    q = np.array([[0.1, -0.4, 0.2, -2.0, 0.1, 1.6, 0.3]])
    uploaded = robots.load("panda_arm")
    assert uploaded.rnea(q, q * 0.5, q * 0.2) == pytest.approx(catalog.rnea(q, q * 0.5, q * 0.2), rel=1e-9, abs=1e-9)
    body = {
        "robot": "panda_arm",
        "path": {"kind": "waypoints", "waypoints": [q[0].tolist(), (q[0] + 0.3).tolist()]},
        "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
        "output": {"dt": 0.01, "format": "joint_trajectory"},
    }
    planned = client.post("/v1/trajectories", json=body)
    assert planned.status_code == 200, planned.text
    message = planned.json()["joint_trajectory"]
    assert message["joint_names"] == robot["joint_names"]
    assert len(message["points"][0]["positions"]) == 7


def test_without_options_a_panda_upload_plans_its_fingers_too(client):
    response = client.post("/v1/robots", json={"name": "panda_whole", "urdf": PANDA})
    assert response.status_code == 201, response.text
    assert response.json()["dof"] == 9 and response.json()["locked_joints"] == {}


def test_joint_limits_yaml_sets_the_limits_and_says_where_each_comes_from(client):
    response = client.post("/v1/robots", json={"name": "ur5_moveit", "urdf": UR5, "joint_limits": UR5_LIMITS_YAML})
    assert response.status_code == 201, response.text
    robot = response.json()
    limits, sources = robot["limits"], robot["limit_sources"]
    assert limits["acceleration"] == [2.0] * 6 and sources["acceleration"] == ["joint_limits.yaml"] * 6
    assert limits["jerk"] == [40.0, 41.0, 42.0, 43.0, 44.0, 45.0] and sources["jerk"] == ["joint_limits.yaml"] * 6
    # A velocity below the URDF's tightens it; one above it is not taken, and a note says so.
    assert limits["velocity"][0] == 1.0 and sources["velocity"][0] == "joint_limits.yaml"
    assert limits["velocity"][2] == 3.15 and sources["velocity"][2] == "urdf"
    assert any("'elbow_joint' a velocity of 99" in note and "URDF's limit is kept" in note for note in robot["notes"])
    assert any("default_velocity_scaling_factor not applied" in note for note in robot["notes"])
    assert sources["torque"] == ["urdf"] * 6
    # The planned motion holds the file's acceleration limit on 1 ms samples, and reaches it.
    body = {
        "robot": "ur5_moveit",
        "path": {"kind": "waypoints", "waypoints": [[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]]},
        "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration"]},
        "output": {"dt": 0.001},
    }
    planned = client.post("/v1/trajectories", json=body)
    assert planned.status_code == 200, planned.text
    qdd = np.array(planned.json()["samples"]["qdd"])
    qd = np.array(planned.json()["samples"]["qd"])
    assert 0.99 <= np.abs(qdd).max() / 2.0 <= 1.005
    assert np.abs(qd[:, 0]).max() <= 1.0 * 1.005


def test_the_default_rule_is_named_where_nothing_gave_a_limit(client):
    uploaded = client.post("/v1/robots", json={"name": "ur5_plain", "urdf": UR5}).json()
    catalog = client.get("/v1/robots/ur5").json()
    # The catalog's ur5 takes 10 rad/s^2 from the service's table; an upload of the same URDF
    # gets the default rule, its URDF's 3.15 rad/s (3.2 on the wrists) reached in 0.2 s.
    assert catalog["limits"]["acceleration"] == [10.0] * 6 and catalog["limit_sources"]["acceleration"] == ["limits.toml"] * 6
    assert uploaded["limits"]["acceleration"] == pytest.approx([15.75] * 3 + [16.0] * 3)
    assert uploaded["limit_sources"]["acceleration"] == ["default: velocity limit / 0.2 s"] * 6
    assert uploaded["limit_sources"]["jerk"] == ["default: acceleration limit / 0.05 s"] * 6
    assert catalog["limit_sources"]["velocity"] == ["urdf"] * 6
    assert client.get("/v1/robots/panda").json()["locked_joints"] == {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}


@pytest.mark.parametrize(
    "options, fragment",
    [
        ({"locked_joints": {"gripper": 0.0}}, "locked_joints names 'gripper'"),
        ({"locked_joints": {"panda_finger_joint1": 0.5}}, "outside the joint's range [0, 0.04]"),
        ({"locked_joints": dict(zip([f"panda_joint{k}" for k in range(1, 8)], [0.0, 0.0, 0.0, -1.5, 0.0, 1.6, 0.0]))
          | {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}},
         "locks every moving joint"),
        ({"joint_limits": "joint_limits:\n  elbow:\n    has_acceleration_limits: true\n    max_acceleration: 1.0\n"},
         "joint_limits names 'elbow'"),
        ({"joint_limits": "joint_limits:\n  panda_joint1:\n    has_acceleration_limits: true\n    max_acceleration: -1.0\n"},
         "joint_limits.panda_joint1.max_acceleration: joint 'panda_joint1': the acceleration limit -1 rad/s^2 from "
         "joint_limits.yaml is outside the accepted range"),
        ({"joint_limits": "joint_limits:\n  panda_joint1:\n    has_acceleration_limits: true\n"},
         "has_acceleration_limits is true but max_acceleration is missing"),
        ({"joint_limits": "joint_limits:\n  panda_joint1: [\n"}, "not valid YAML at line"),
        ({"joint_limits": {"panda_joint1": {"max_velocity": 1.0}}}, "must hold a 'joint_limits' mapping"),
        ({"joint_limits": {"joint_limits": {"panda_joint1": {"max_speed": 1.0}}}}, "unknown key 'max_speed'"),
        ({"joint_limits": {"joint_limits": {"panda_joint1": {"has_velocity_limits": "yes", "max_velocity": 1.0}}}},
         "has_velocity_limits must be true or false"),
    ],
)
def test_bad_options_are_a_422_naming_the_joint(client, options, fragment):
    response = client.post("/v1/robots", json={"name": "panda_bad", "urdf": PANDA, **options})
    assert response.status_code == 422, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    assert fragment in response.json()["detail"]
    assert client.get("/v1/robots/panda_bad").status_code == 404


def test_a_non_finite_locked_value_is_refused():
    with pytest.raises(InvalidUpload, match="finite number"):
        upload_options({"panda_finger_joint1": float("nan")})


def test_the_same_urdf_with_other_options_under_one_name_is_a_conflict(client):
    first = client.post("/v1/robots", json={"name": "panda_twice", "urdf": PANDA, "locked_joints": FINGERS})
    assert first.status_code == 201
    again = client.post("/v1/robots", json={"name": "panda_twice", "urdf": PANDA, "locked_joints": FINGERS})
    assert again.status_code == 201 and again.json()["dof"] == 7
    other = client.post("/v1/robots", json={"name": "panda_twice", "urdf": PANDA})
    assert other.status_code == 409 and "other options" in other.json()["detail"]


def test_options_are_kept_in_the_store_for_every_process(tmp_path):
    """A process that did not see the upload (a fresh cache on the same directory, as another
    worker or a restart) builds the same reduced robot with the same limits."""
    previous = robots.upload_store()
    try:
        robots.configure_uploads(tmp_path)
        options = upload_options(FINGERS, {"joint_limits": {"panda_joint1": {"has_jerk_limits": True, "max_jerk": 123.0}}})
        robots.register_urdf(PANDA, "panda_kept", options)
        robots.configure_uploads(tmp_path)  # empties this process's cache: only the store remains
        robot = robots.load("panda_kept")
        assert robot.dof == 7 and robot.locked_joints == FINGERS
        assert any("panda_finger_joint2 = 0.02" in note for note in robot.notes)
        assert robot.limits.jerk[0] == 123.0 and robot.limit_sources["jerk"][0] == "joint_limits.yaml"
        assert [upload.name for upload in robots.list_uploads()] == ["panda_kept"]
    finally:
        robots.configure_uploads(previous.data_dir, max_uploads=previous.max_uploads, max_bytes=previous.max_bytes)


OLD_SCHEMA = """
CREATE TABLE urdfs (digest TEXT PRIMARY KEY, urdf TEXT NOT NULL, bytes INTEGER NOT NULL);
CREATE TABLE robots (name TEXT PRIMARY KEY, digest TEXT NOT NULL REFERENCES urdfs (digest), dof INTEGER NOT NULL,
                     created REAL NOT NULL);
"""


def test_a_store_written_before_options_existed_still_loads_and_is_migrated(tmp_path):
    import hashlib

    database = tmp_path / "uploads.sqlite3"
    digest = hashlib.sha256(UR5.encode()).hexdigest()
    with sqlite3.connect(database) as connection:
        connection.executescript(OLD_SCHEMA)
        connection.execute("INSERT INTO urdfs VALUES (?, ?, ?)", (digest, UR5, len(UR5.encode())))
        connection.execute("INSERT INTO robots VALUES (?, ?, ?, ?)", ("old_ur5", digest, 6, time.time()))
    previous = robots.upload_store()
    try:
        robots.configure_uploads(tmp_path)
        # Read as it is (reading never writes) ...
        assert robots.load("old_ur5").dof == 6
        assert robots.list_uploads()[0].options == ""
        # ... and migrated by the first write, the old upload intact.
        robots.register_urdf(PANDA, "new_panda", upload_options(FINGERS))
        with sqlite3.connect(database) as connection:
            columns = [row[1] for row in connection.execute("PRAGMA table_info(robots)")]
        assert "options" in columns
        robots.configure_uploads(tmp_path)
        assert robots.load("old_ur5").dof == 6 and robots.load("new_panda").dof == 7
    finally:
        robots.configure_uploads(previous.data_dir, max_uploads=previous.max_uploads, max_bytes=previous.max_bytes)


def test_a_stored_default_payload_keeps_its_collision_radius():
    from toptraj.robots.equipment import payload
    from toptraj.robots.upload_options import UploadOptions

    options = UploadOptions(payload=payload(1.5, [0.05, 0.0, 0.0], frame="hand", radius=0.04))
    assert UploadOptions.from_json(options.to_json()).payload == options.payload


def test_a_maximum_whose_flag_is_false_is_noted_as_not_applied(client):
    """MoveIt applies a max_* only where its has_*_limits is true; the upload does the same and
    its notes say which values were left aside."""
    limits = {"joint_limits": {"shoulder_pan_joint": {"has_acceleration_limits": False, "max_acceleration": 3},
                               "elbow_joint": {"max_jerk": 50.0}}}
    response = client.post("/v1/robots", json={"name": "ur5_flag_off", "urdf": UR5, "joint_limits": limits})
    assert response.status_code == 201, response.text
    robot = response.json()
    assert robot["limits"]["acceleration"][0] == pytest.approx(15.75)  # the default rule, not 3
    assert robot["limit_sources"]["acceleration"][0] == "default: velocity limit / 0.2 s"
    assert any("max_acceleration of shoulder_pan_joint (3) not applied: has_acceleration_limits is false" in note
               for note in robot["notes"])
    assert any("max_jerk of elbow_joint (50.0) not applied: has_jerk_limits is false or absent" in note for note in robot["notes"])
