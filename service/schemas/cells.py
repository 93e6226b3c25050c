"""Schemas of ``POST /v1/cells``: arms sharing a workspace, each along its own joint path,
timed together so that they keep a clearance (DESIGN.md, HTTP contract)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from toptraj.robots.ranges import GRAVITY
from toptraj.service.schemas.common import Schema, signed
from toptraj.service.schemas.equipment import (
    BasePosition,
    PayloadRequest,
    Quaternion,
    RotationMatrix,
    checked_orientation,
    checked_rotation,
)
from toptraj.service.schemas.trajectories import JointVector, Name

#: Arms a request may list (the planner serves up to ``coordination.cell.MAX_ARMS``; more are
#: refused with a 422 saying so).
MAX_CELL_ARMS = 8
#: Waypoints per arm.
MAX_CELL_WAYPOINTS = 100
#: Fields of other kinds of path (the trajectory endpoint's ``path``), refused with advice.
_PATH_FIELDS = ("interpolation", "max_deviation", "continuous", "revolutions")
OTHER_PATH_KEYS = ("path", "kind", "points", "positions", "poses", "line", "start", "goal", "frame", *_PATH_FIELDS)


class BasePose(Schema):
    """Where an arm's base stands in the world: p_world = rotation p_base + position (the
    rotation given as a matrix or, as a trajectory's ``mounting``, a unit quaternion)."""

    position: BasePosition = Field(default=[0.0, 0.0, 0.0], description="The base's origin [x, y, z] (m), world frame.")
    rotation: RotationMatrix | None = Field(
        default=None,
        description="Rotation matrix (rows) from the base's axes to the world's: orthonormal within 1e-3 (then made "
        "exact), determinant +1; default the identity. [[-1,0,0],[0,-1,0],[0,0,1]] turns the base half a turn about z. "
        "Give this or orientation.",
    )
    orientation: Quaternion | None = Field(
        default=None,
        description="The base's orientation as a unit quaternion [qx, qy, qz, qw] (norm 1 within 1e-3); [0, 0, 1, 0] "
        "turns it half a turn about z. Give this or rotation.",
    )

    check_orientation = field_validator("orientation")(checked_orientation)
    check_rotation = field_validator("rotation")(checked_rotation)

    @model_validator(mode="after")
    def _one_rotation(self):
        if self.orientation is not None and self.rotation is not None:
            raise ValueError("give base.orientation or base.rotation, not both")
        return self


class CellArmRequest(Schema):
    """One arm of the cell: its robot, base pose, joint path and limit scales."""

    robot: Name = Field(description="Robot name (GET /v1/robots).")
    base: BasePose = Field(default=BasePose(), description="The base pose in the world.")
    waypoints: list[JointVector] = Field(
        min_length=2,
        max_length=MAX_CELL_WAYPOINTS,
        description="Joint configurations (rad, m), one row each, through which a C2 cubic spline runs.",
    )
    velocity_scale: Annotated[float, Field(gt=0.0, le=1.0)] = Field(
        default=1.0, description="Factor on the robot's velocity limits."
    )
    acceleration_scale: Annotated[float, Field(gt=0.0, le=1.0)] = Field(
        default=1.0, description="Factor on the robot's acceleration limits."
    )
    torque_scale: Annotated[float, Field(gt=0.0, le=1.0)] = Field(default=1.0, description="Factor on the robot's torque limits.")
    payload: PayloadRequest | None = Field(
        default=None,
        description="What the arm carries at its tool (mass, centre of mass, inertia): its torques, torque limits "
        "and `tau` include it; default the upload's payload, else none.",
    )

    @model_validator(mode="before")
    @classmethod
    def _joint_waypoints_only(cls, data):
        given = sorted(key for key in OTHER_PATH_KEYS if isinstance(data, dict) and key in data)
        if given:
            raise ValueError(
                f"{', '.join(given)}: an arm of a cell follows joint waypoints only (a C2 cubic spline through "
                "`waypoints`); Cartesian lines, free motions and other path kinds are served by POST /v1/trajectories. "
                "Give each arm `waypoints` (joint values, rad or m), e.g. an inverse kinematics solution at points "
                "along the line"
            )
        return data


class CellRequest(Schema):
    """Arms in one workspace, each along its own path, to be timed together."""

    arms: list[CellArmRequest] = Field(
        min_length=1,
        max_length=MAX_CELL_ARMS,
        description="The arms: two coordinated in full, three or four by prioritized planning (each arm on its own "
        "optimum, waiting at its start; every order tried); more are refused.",
    )
    clearance: Annotated[float, Field(ge=0.0, le=1.0)] = Field(
        default=0.01, description="Smallest distance (m) the arms' link capsules keep from each other at all times."
    )
    constraints: list[Literal["velocity", "acceleration", "torque"]] = Field(
        default=["velocity", "acceleration", "torque"],
        min_length=1,
        max_length=3,
        description="Limits each arm keeps (held on a dense resampling of the answer).",
    )
    gravity: Annotated[list[Annotated[float, signed(GRAVITY)]], Field(min_length=3, max_length=3)] | None = Field(
        default=None, description="Gravity in the world (m/s^2); default the robots' own, [0, 0, -9.81] for the catalog arms."
    )
    dt: Annotated[float, Field(ge=1e-3, le=1.0)] = Field(default=0.01, description="Sample period (s) of the answer.")
    format: Literal["samples", "joint_trajectory", "csv"] = Field(
        default="samples",
        description="The answer's shape, as the trajectory endpoint's `output.format`: `samples` (each arm's arrays "
        "t, q, qd, qdd, tau), `joint_trajectory` (one trajectory_msgs/JointTrajectory per arm, with effort), `csv` "
        "(text/csv: a header `t,arms[i].q.<joint>,…`, the answer's facts as `# key: value` lines, a row per "
        "sample; also chosen by `Accept: text/csv`). Every arm on the same times.",
    )
    exact_period: bool | None = Field(
        default=None,
        description="Samples on whole periods `dt`, the final state included: the cell's motion is slowed uniformly "
        "(by less than one period) to end on a sample; `duration` stays the planned one, `sampled_duration` is the "
        "last sample's time. Default: true for `joint_trajectory` and `csv`, false for `samples` (samples every dt "
        "plus the final instant).",
    )
