"""The robot catalog: the bundled paper arms, the fixed-base arms of ``example-robot-data``, and
URDFs uploaded at run time (kept in memory under a content-hash id).

Models are built once per process and shared read-only; see ``Robot.data`` for per-thread state.
"""

from __future__ import annotations

import hashlib
import re
import threading
from dataclasses import dataclass
from functools import cache
from importlib import resources
from os.path import join

import numpy as np
import pinocchio as pin

from robots.errors import RobotConflict, UnknownRobot
from robots.limits import limits_for
from robots.robot import Robot, tangent_position_limits
from robots.urdf_check import check_urdf

#: Bundled URDFs: name -> end-effector frame.
BUNDLED = {"geering_2r": "hand", "yamamoto_2r": "tip", "lecture_3r": "hand"}


@dataclass(frozen=True)
class _ExampleArm:
    """A fixed-base arm of example-robot-data: its loader name, the joints locked at a fixed
    position (grippers), and its end-effector frame (``None``: the last body frame)."""

    loader: str
    locked: dict[str, float]
    end_effector: str | None


#: The fixed-base arms of example-robot-data with complete URDF limits. Grippers are locked open
#: at 0 so that every remaining joint is an arm joint. ``so100`` is left out: its gripper joint and
#: a link share one name, which Pinocchio cannot reduce.
EXAMPLE_ARMS = {
    "ur3": _ExampleArm("ur3", {}, "tool0"),
    "ur3_limited": _ExampleArm("ur3_limited", {}, "tool0"),
    "ur3_gripper": _ExampleArm("ur3_gripper", {}, "tool0"),
    "ur5": _ExampleArm("ur5", {}, "tool0"),
    "ur5_limited": _ExampleArm("ur5_limited", {}, "tool0"),
    "ur5_gripper": _ExampleArm("ur5_gripper", {}, "tool0"),
    "ur10": _ExampleArm("ur10", {}, "tool0"),
    "ur10_limited": _ExampleArm("ur10_limited", {}, "tool0"),
    "panda": _ExampleArm(
        "panda", {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}, "panda_hand_tcp"
    ),
    "kinova": _ExampleArm("kinova", {}, "j2s6s200_end_effector"),
    "z1": _ExampleArm("z1", {"jointGripper": 0.0}, None),
    "xarm7": _ExampleArm("xarm7", {}, "link_eef"),
    "talos_arm": _ExampleArm("talos_arm", {"gripper_left_joint": 0.0}, None),
    "so101": _ExampleArm("so101", {"gripper": 0.0}, "gripper_frame_link"),
    "asr_twodof": _ExampleArm("asr_twodof", {}, "Tip"),
    "finger_edu": _ExampleArm("finger_edu", {}, "finger_tip_link"),
}

_uploads: dict[str, Robot] = {}
_upload_hashes: dict[str, str] = {}
_lock = threading.Lock()


def _last_body_frame(model: pin.Model) -> str:
    bodies = [frame.name for frame in model.frames if frame.type == pin.FrameType.BODY]
    return bodies[-1]


def _robot_from_model(name: str, model: pin.Model, source: str, end_effector: str | None) -> Robot:
    lower, upper = tangent_position_limits(model)
    limits = limits_for(name, lower, upper, np.array(model.velocityLimit), np.array(model.effortLimit))
    return Robot.from_model(name, model, source, end_effector or _last_body_frame(model), limits)


def _example_urdf_path(loader_name: str) -> str:
    from example_robot_data.robots_loader import ROBOTS
    from example_robot_data.utils import getModelPath

    loader = ROBOTS[loader_name]
    subpath = join(loader.path, loader.urdf_subpath, loader.urdf_filename)
    return join(getModelPath(subpath), subpath)


@cache
def _load_catalog_robot(name: str) -> Robot:
    if name in BUNDLED:
        urdf = resources.files("robots").joinpath(f"urdf/{name}.urdf").read_text()
        return _robot_from_model(name, pin.buildModelFromXML(urdf), "bundled", BUNDLED[name])
    arm = EXAMPLE_ARMS[name]
    model = pin.buildModelFromUrdf(_example_urdf_path(arm.loader))
    if arm.locked:
        reference = pin.neutral(model)
        for joint_name, value in arm.locked.items():
            reference[model.joints[model.getJointId(joint_name)].idx_q] = value
        locked_ids = [model.getJointId(joint_name) for joint_name in arm.locked]
        model = pin.buildReducedModel(model, locked_ids, reference)
    return _robot_from_model(name, model, "example-robot-data", arm.end_effector)


def catalog_names() -> list[str]:
    """Names of every robot that ``load`` knows, bundled first, uploads last."""
    with _lock:
        uploaded = sorted(_uploads)
    return [*BUNDLED, *EXAMPLE_ARMS, *uploaded]


def load(name: str) -> Robot:
    """The robot called ``name``; built once per process.

    Raises:
        UnknownRobot: no bundled, example-robot-data or uploaded robot has that name.
    """
    with _lock:
        if name in _uploads:
            return _uploads[name]
    if name in BUNDLED or name in EXAMPLE_ARMS:
        return _load_catalog_robot(name)
    raise UnknownRobot(name, catalog_names())


_NAME_PATTERN = re.compile(r"^[A-Za-z][A-Za-z0-9_.-]{0,63}$")


def register_urdf(urdf: str, name: str | None = None) -> Robot:
    """Check ``urdf``, build its model and keep it under ``name`` (default: ``urdf-`` and the
    first 12 hex digits of the content's SHA-256). Uploading the same content twice is harmless.

    Raises:
        InvalidURDF: the text is not a usable fixed-base arm (see ``check_urdf``).
        RobotConflict: ``name`` is a catalog robot or holds a different upload.
    """
    digest = hashlib.sha256(urdf.encode()).hexdigest()
    if name is None:
        name = f"urdf-{digest[:12]}"
    elif not _NAME_PATTERN.match(name):
        raise RobotConflict(
            f"name {name!r} must start with a letter and hold at most 64 letters, digits, '_', '.' or '-'"
        )
    if name in BUNDLED or name in EXAMPLE_ARMS:
        raise RobotConflict(f"name {name!r} belongs to a catalog robot; choose another")
    with _lock:
        if name in _uploads:
            if _upload_hashes[name] == digest:
                return _uploads[name]
            raise RobotConflict(f"name {name!r} already holds a different URDF")
    model = check_urdf(urdf)
    robot = _robot_from_model(name, model, "upload", None)
    with _lock:
        _uploads[name] = robot
        _upload_hashes[name] = digest
    return robot
