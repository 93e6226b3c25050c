"""Schemas of the robot resource."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, field_validator

from toptraj.robots.uploads import MAX_NAME_CHARS, NAME_PATTERN
from toptraj.service.schemas.common import Schema
from toptraj.service.schemas.equipment import MountingRequest, PayloadRequest

MAX_URDF_CHARS = 1_000_000


Source = Literal["bundled", "example-robot-data", "upload"]


class RobotSummary(BaseModel):
    """One line of the catalog."""

    name: str = Field(description="The robot's name, as requests give it.")
    dof: int = Field(description="Degrees of freedom (actuated joints).")
    source: Source = Field(description="`bundled` (the papers' arms), `example-robot-data` or `upload`.")


class RobotLimits(BaseModel):
    """Per-joint limits in SI units (rad, rad/s, rad/s^2, rad/s^3, N m); ``null`` is unlimited."""

    position_lower: list[float | None] = Field(description="Lower position limits (rad, m); null for a continuous joint.")
    position_upper: list[float | None] = Field(description="Upper position limits (rad, m); null for a continuous joint.")
    velocity: list[float | None] = Field(description="Velocity limits (rad/s, m/s).")
    acceleration: list[float | None] = Field(description="Acceleration limits (rad/s^2, m/s^2).")
    jerk: list[float | None] = Field(description="Jerk limits (rad/s^3, m/s^3).")
    torque: list[float | None] = Field(description="Torque (N m) or force (N) limits.")


class RobotLimitSources(BaseModel):
    """Where each joint's limit comes from: `urdf`, `limits.toml` (the service's table for catalog
    robots), `joint_limits.yaml` (given with the upload) or `default: ...` (the rule applied)."""

    position_lower: list[str] = Field(description="Source of each lower position limit.")
    position_upper: list[str] = Field(description="Source of each upper position limit.")
    velocity: list[str] = Field(description="Source of each velocity limit.")
    acceleration: list[str] = Field(description="Source of each acceleration limit.")
    jerk: list[str] = Field(description="Source of each jerk limit.")
    torque: list[str] = Field(description="Source of each torque limit.")


class PayloadPublic(BaseModel):
    """A payload as the robot carries it."""

    mass: float = Field(description="Mass (kg).")
    center_of_mass: list[float] = Field(description="Centre of mass [x, y, z] (m) in `frame`.")
    inertia: list[list[float]] = Field(description="Rotational inertia about the centre of mass, in `frame`'s axes (kg m^2), 3x3.")
    frame: str = Field(description="The frame holding it.")
    radius: float = Field(default=0.0, description="Radius (m) of its collision sphere about the centre of mass (0: it does not collide).")


class RobotPublic(BaseModel):
    """A robot as the service sees it."""

    name: str = Field(description="The robot's name, as requests give it.")
    dof: int = Field(description="Degrees of freedom (actuated joints).")
    source: str = Field(description="`bundled` (the papers' arms), `example-robot-data` or `upload`.")
    joint_names: list[str] = Field(description="Joint names, in the order of every per-joint list.")
    end_effector: str = Field(description="The frame Cartesian paths and tool speeds refer to by default.")
    limits: RobotLimits = Field(description="Per-joint limits, SI units.")
    limit_sources: RobotLimitSources = Field(description="Where each limit comes from, per joint.")
    locked_joints: dict[str, float] = Field(
        description="Joints of the URDF fixed at a value (rad, m) and left out of joint_names (grippers)."
    )
    notes: list[str] = Field(description="What was not used or was changed: mesh files, limits not applied.")
    payload: PayloadPublic | None = Field(
        default=None, description="The payload the robot carries unless a request gives its own (an upload's option); null: none."
    )


class RobotCreate(Schema):
    """An uploaded URDF, optionally under a chosen name."""

    name: str | None = Field(
        default=None,
        max_length=MAX_NAME_CHARS,
        pattern=f"^{NAME_PATTERN.pattern}$",
        description="Name to keep it under (a letter, then up to 63 letters, digits, `_`, `.` or `-`); "
        "default `urdf-` plus a content hash.",
    )
    urdf: str = Field(max_length=MAX_URDF_CHARS, description="The URDF text (fixed-base arm).")
    locked_joints: dict[str, float] | None = Field(
        default=None,
        max_length=64,
        description="Joints to fix at a value (rad, m), e.g. a gripper's fingers: "
        '`{"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}`. The robot plans the other joints.',
    )
    payload: PayloadRequest | None = Field(
        default=None,
        description="The payload the robot carries by default (mass, centre of mass, inertia; as a trajectory "
        "request's `payload`): requests that give none plan with it.",
    )
    joint_limits: str | dict[str, Any] | None = Field(
        default=None,
        description="Limits in the form of MoveIt's `joint_limits.yaml`: its text, or the same structure as "
        "JSON (`{\"joint_limits\": {joint: {\"has_acceleration_limits\": true, \"max_acceleration\": 10.0, ...}}}`). "
        "Acceleration and jerk limits (rad/s^2, rad/s^3) are taken as given; velocity and effort limits "
        "(rad/s, N m) only tighten the URDF's. The robot's `limit_sources` and `notes` say what was applied. "
        "Each limit lies in the range of its kind (the range of `timing.limits` of a trajectory request: velocity "
        "[1e-6, 1e3], acceleration [1e-6, 1e5], jerk [1e-6, 1e8], effort [1e-6, 1e5]). The text holds at most "
        "100,000 characters, 32 levels of nesting, 10,000 values with its aliases expanded and 1,000 aliases; keys "
        "are strings, each once per mapping; one document.",
    )
    allowed_collisions: str | list[Annotated[list[str], Field(min_length=2, max_length=2)]] | None = Field(
        default=None,
        max_length=2_000,
        description="Pairs of links allowed to touch, not checked for self-collision (path.self_collision and the "
        "search): an SRDF's text (its `<disable_collisions link1=... link2=.../>` are read, at most 200,000 "
        "characters, no DOCTYPE) or a list of `[link, link]` pairs (at most 2,000). Adjacent links are never "
        "checked; an allowed pair also covers the links fixed to its links.",
    )

    @field_validator("allowed_collisions", mode="before")
    @classmethod
    def _pairs(cls, value):
        """A list of pairs checked by the library's rules first: its words, not the union's."""
        if value is None or isinstance(value, str):
            return value
        from toptraj.robots.srdf import InvalidCollisionList, allowed_pairs

        try:
            allowed_pairs(value)
        except InvalidCollisionList as error:
            raise ValueError(error.detail) from None
        return value


MAX_CONFIGURATIONS = 1_000


class SkeletonRequest(Schema):
    """Joint configurations to draw (rad, m), one row each."""

    q: list[Annotated[list[float], Field(min_length=1, max_length=64)]] = Field(
        min_length=1, max_length=MAX_CONFIGURATIONS, description="Joint configurations (rad, m), one row each."
    )
    mounting: MountingRequest | None = Field(
        default=None, description="The base pose in the world, as a trajectory request's `mounting`: positions are then world positions."
    )


class SkeletonPublic(BaseModel):
    """World positions (m) of each joint origin and of the end effector, per configuration:
    ``positions[k][i]`` is point ``points[i]`` in configuration k."""

    points: list[str] = Field(description="Names of the points: the joints, then the end effector.")
    positions: list[list[list[float]]] = Field(description="World positions (m): positions[k][i] = [x, y, z] of point i in configuration k.")
