"""The robot catalog: the bundled paper arms and the fixed-base arms of ``example-robot-data``.
(Uploaded URDFs live in ``toptraj.robots.uploads``; ``robots.load`` looks in both.)

Models are built once per process and shared read-only; see ``Robot.data`` for per-thread state.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from os.path import join

import numpy as np
import pinocchio as pin

from toptraj.robots.limits import limits_with_sources
from toptraj.robots.robot import Robot, tangent_position_limits

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


def _last_body_frame(model: pin.Model) -> str:
    bodies = [frame.name for frame in model.frames if frame.type == pin.FrameType.BODY]
    return bodies[-1]


def robot_from_model(
    name: str,
    model: pin.Model,
    source: str,
    end_effector: str | None,
    given_limits: dict[str, np.ndarray] | None = None,
    locked_joints: dict[str, float] | None = None,
    notes: tuple[str, ...] = (),
) -> Robot:
    """``model`` as a ``Robot`` with its limits (URDF values completed by ``data/limits.toml``,
    tightened or completed by ``given_limits`` from an upload's joint_limits.yaml) and where
    each comes from; ``end_effector`` ``None`` means the last body frame."""
    lower, upper = tangent_position_limits(model)
    joint_names = tuple(model.names[1:])
    limits, sources, limit_notes = limits_with_sources(
        name, lower, upper, np.array(model.velocityLimit), np.array(model.effortLimit), given_limits, joint_names
    )
    return Robot.from_model(
        name, model, source, end_effector or _last_body_frame(model), limits, sources, locked_joints,
        (*notes, *limit_notes),
    )


_robot_from_model = robot_from_model  # the former, private name


def example_urdf_path(loader_name: str) -> str:
    """File path of the URDF of example-robot-data's robot ``loader_name``."""
    from example_robot_data.robots_loader import ROBOTS
    from example_robot_data.utils import getModelPath

    loader = ROBOTS[loader_name]
    subpath = join(loader.path, loader.urdf_subpath, loader.urdf_filename)
    return join(getModelPath(subpath), subpath)


#: The catalog robots built in this process, by name.
_built: dict[str, Robot] = {}


def load_catalog_robot(name: str) -> Robot:
    """The catalog robot ``name`` (a key of ``BUNDLED`` or ``EXAMPLE_ARMS``), built once per
    process (two threads asking at once may both build it; one of the two is kept)."""
    robot = _built.get(name)
    if robot is None:
        robot = _built.setdefault(name, _build(name))
    return robot


def catalog_robot_built(name: str) -> bool:
    """Whether the catalog robot ``name`` is built already: ``load_catalog_robot`` returns it at once."""
    return name in _built


def _build(name: str) -> Robot:
    """Build the catalog robot ``name`` from its URDF."""
    if name in BUNDLED:
        urdf = resources.files("toptraj.robots").joinpath(f"urdf/{name}.urdf").read_text()
        return robot_from_model(name, pin.buildModelFromXML(urdf), "bundled", BUNDLED[name])
    arm = EXAMPLE_ARMS[name]
    model = pin.buildModelFromUrdf(example_urdf_path(arm.loader))
    if arm.locked:
        reference = pin.neutral(model)
        for joint_name, value in arm.locked.items():
            reference[model.joints[model.getJointId(joint_name)].idx_q] = value
        locked_ids = [model.getJointId(joint_name) for joint_name in arm.locked]
        model = pin.buildReducedModel(model, locked_ids, reference)
    return robot_from_model(name, model, "example-robot-data", arm.end_effector, locked_joints=arm.locked)


def is_catalog_robot(name: str) -> bool:
    """Whether ``name`` is a bundled or example-robot-data robot."""
    return name in BUNDLED or name in EXAMPLE_ARMS


def catalog_names() -> list[str]:
    """Names of the catalog robots, bundled first (uploads: ``robots.list_uploads``)."""
    return [*BUNDLED, *EXAMPLE_ARMS]
