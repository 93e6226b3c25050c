"""Schemas of ``POST /v1/trajectories`` (DESIGN.md, HTTP contract)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, Discriminator, Field, Tag

from planners import ranges
from service.schemas.common import Schema, bounded, signed

MAX_WAYPOINTS = 1_000
MAX_JOINTS = 64
#: Longest robot, frame or method name accepted (names are echoed in error messages).
MAX_NAME_CHARS = 256


def _joint_vector(item) -> type:
    """A list of one value per joint."""
    return Annotated[list[item], Field(min_length=1, max_length=MAX_JOINTS)]


JointVector = _joint_vector(signed(ranges.COORDINATE))
Name = Annotated[str, Field(max_length=MAX_NAME_CHARS)]


class WaypointsPath(Schema):
    """Joint waypoints, interpolated by a C2 cubic spline, by straight segments that stop at
    each waypoint, or by straight segments joined by circular blends."""

    kind: Literal["waypoints"] = "waypoints"
    waypoints: list[JointVector] = Field(
        min_length=2, max_length=MAX_WAYPOINTS, description="Joint configurations (rad, m), one row each."
    )
    interpolation: Literal["spline", "linear", "blend", "via"] = Field(
        default="spline",
        description="`spline` (C2 cubic), `linear` (straight, stopping at each waypoint), `blend` "
        "(straight segments joined by circular blends within path.max_deviation of each waypoint, as "
        "MoveIt's TOTG) or `via` (per-joint cubic/quintic segments through via points; with "
        "timing.method cubic or quintic).",
    )
    max_deviation: bounded(ranges.MAX_DEVIATION) | None = Field(
        default=None,
        description="`blend` only: largest joint-space distance (Euclidean norm, rad or m) of a blend from "
        "its waypoint; default 0.1.",
    )


class CartesianPathRequest(Schema):
    """Straight lines of a frame through positions (orientation free) or poses (orientation by
    slerp), from the pose of the start configuration; joint path by inverse kinematics."""

    kind: Literal["cartesian"]
    frame: Name | None = Field(default=None, description="Frame to move; default the robot's end effector.")
    start: JointVector = Field(description="Start joint configuration (rad, m).")
    positions: list[Annotated[list[float], Field(min_length=3, max_length=3)]] | None = Field(
        default=None, min_length=1, max_length=MAX_WAYPOINTS, description="[x, y, z] in m, world frame."
    )
    poses: list[Annotated[list[float], Field(min_length=7, max_length=7)]] | None = Field(
        default=None, min_length=1, max_length=MAX_WAYPOINTS, description="[x, y, z, qx, qy, qz, qw]."
    )


class FreePathRequest(Schema):
    """Start and goal only: the path and its timing are optimized together (timing.method
    `collocation`)."""

    kind: Literal["free"]
    start: JointVector = Field(description="Start configuration (rad, m), at rest unless timing.boundary says otherwise.")
    goal: JointVector = Field(description="Goal configuration (rad, m).")
    revolutions: bool = Field(
        default=True, description="Whether continuous joints may reach their goal one revolution either way."
    )
    obstacles: list[dict] = Field(default=[], max_length=0, description="Not supported yet: must be empty.")


def _path_kind(value) -> str:
    """The path's ``kind``; waypoints when the request leaves it out."""
    if isinstance(value, dict):
        return value.get("kind", "waypoints")
    return getattr(value, "kind", "waypoints")


PathRequest = Annotated[
    Annotated[WaypointsPath, Tag("waypoints")]
    | Annotated[CartesianPathRequest, Tag("cartesian")]
    | Annotated[FreePathRequest, Tag("free")],
    Discriminator(
        _path_kind, custom_error_type="path_kind", custom_error_message="path.kind must be 'waypoints', 'cartesian' or 'free'"
    ),
]


class LimitsRequest(Schema):
    """Per-joint overrides and scale factors of the robot's limits, and limits on the speed of a
    tool frame (SI units)."""

    velocity: _joint_vector(bounded(ranges.VELOCITY)) | None = None
    acceleration: _joint_vector(bounded(ranges.ACCELERATION)) | None = None
    jerk: _joint_vector(bounded(ranges.JERK)) | None = None
    torque: _joint_vector(bounded(ranges.TORQUE)) | None = None
    velocity_scale: bounded(ranges.SCALE) | None = None
    acceleration_scale: bounded(ranges.SCALE) | None = None
    jerk_scale: bounded(ranges.SCALE) | None = None
    torque_scale: bounded(ranges.SCALE) | None = None
    tool_speed: bounded(ranges.TOOL_SPEED) | None = Field(
        default=None, description="Largest linear speed of the tool frame's origin (m/s)."
    )
    tool_angular_speed: bounded(ranges.TOOL_ANGULAR_SPEED) | None = Field(
        default=None, description="Largest angular speed of the tool frame (rad/s)."
    )
    tool_frame: Name | None = Field(
        default=None, description="Frame whose speed tool_speed and tool_angular_speed limit; default the robot's end effector."
    )


class Boundary(Schema):
    """Joint velocities (rad/s) and accelerations (rad/s^2) at the ends, tangent to the path;
    absent means rest."""

    start_velocity: _joint_vector(signed(ranges.VELOCITY)) | None = None
    end_velocity: _joint_vector(signed(ranges.VELOCITY)) | None = None
    start_acceleration: _joint_vector(signed(ranges.ACCELERATION)) | None = None
    end_acceleration: _joint_vector(signed(ranges.ACCELERATION)) | None = None


class CostRequest(Schema):
    """Weights of the cost integral of (1 + beta |tau|^2) dt (min_cost): beta in 1/(N m)^2."""

    torque_weight: Annotated[float, Field(ge=0.0, le=1e3)] = 0.0


class TrapezoidRequest(Schema):
    """Switching fractions of the trapezoidal law (Angeles 6.1): acceleration ends at tau1 and
    deceleration starts at tau2, as fractions of the duration."""

    tau1: bounded(ranges.TRAPEZOID_FRACTION) = 1.0 / 3.0
    tau2: bounded(ranges.TRAPEZOID_FRACTION) = 2.0 / 3.0


class TimingRequest(Schema):
    """How to time the path."""

    method: Name = Field(
        default="phase_plane",
        description="`phase_plane` (time-optimal, default), `toppra`, `min_cost` (minimum of the "
        "integral of 1 + beta |tau|^2), `jerk_limited` (time-optimal with jerk limits too), `ruckig` "
        "(jerk-limited, two waypoints), a time law "
        "(`cubic`, `quintic`, `trapezoidal`, `cycloidal`), or `collocation` (free path).",
    )
    constraints: list[Literal["velocity", "acceleration", "torque", "jerk"]] = Field(
        default=["velocity", "acceleration", "torque"],
        max_length=4,
        description="Limits to respect; jerk only with jerk_limited, the time laws and ruckig.",
    )
    limits: LimitsRequest = LimitsRequest()
    duration: bounded(ranges.DURATION) | None = Field(
        default=None, description="Seconds, for the classical time laws and via points."
    )
    boundary: Boundary = Boundary()
    cost: CostRequest = CostRequest()
    trapezoid: TrapezoidRequest = TrapezoidRequest()
    grid_points: Annotated[int, Field(ge=2, le=20_000)] | None = Field(
        default=None, description="Number of grid intervals over the path; default chosen from it."
    )
    limit_margin: Annotated[float, Field(ge=0.0, le=0.5)] = Field(
        default=0.0,
        description="Fraction of every velocity, acceleration, jerk and torque limit kept in reserve: "
        "the motion is planned under the limits times (1 - margin). With a positive margin no returned "
        "sample exceeds any limit; with 0, no limit is exceeded by more than 0.3 % on a dense resampling.",
    )


class OutputRequest(Schema):
    """Sampling of the returned trajectory."""

    dt: bounded(ranges.DT) = Field(default=0.01, description="Sample period (s).")


class TrajectoryRequest(Schema):
    """A motion to plan."""

    robot: Name = Field(description="Catalog or uploaded robot name, e.g. `ur5`.")
    path: PathRequest
    timing: TimingRequest = TimingRequest()
    output: OutputRequest = OutputRequest()


class SamplesPublic(BaseModel):
    """Time samples; ``q[k]`` holds one value per joint at ``t[k]``."""

    t: list[float]
    q: list[list[float]]
    qd: list[list[float]]
    qdd: list[list[float]]
    tau: list[list[float]]


class SwitchPoint(BaseModel):
    s: float
    kind: str


class PhasePlanePublic(BaseModel):
    """The timing in the phase plane: path speed ``sd`` and maximum velocity curve ``sd_max``
    (1/s) over s in [0, 1]."""

    s: list[float]
    sd: list[float]
    sd_max: list[float | None]
    switch_points: list[SwitchPoint] = []


class UtilizationPublic(BaseModel):
    """Peak |value| / limit per joint over a dense resampling (1.0: the limit binds); jerk
    for timings with a finite jerk (jerk_limited, time laws, ruckig)."""

    velocity: list[float]
    acceleration: list[float]
    torque: list[float]
    jerk: list[float] | None = None
    tool_speed: float | None = Field(default=None, description="Peak tool speed / timing.limits.tool_speed, when limited.")
    tool_angular_speed: float | None = Field(
        default=None, description="Peak angular tool speed / timing.limits.tool_angular_speed, when limited."
    )


class BindingPublic(BaseModel):
    """The limit that set a minimal duration (time laws): its kind, joint and place."""

    kind: str
    joint: str | None
    s: float


class ConditioningPublic(BaseModel):
    """Frobenius condition number of the end effector's Jacobian along the trajectory (1:
    isotropic; null: singular), translations over the characteristic length L (m)."""

    kappa_min: float | None
    kappa_max: float | None
    characteristic_length: float


class TrajectoryResponse(BaseModel):
    """A timed joint trajectory with its torques."""

    robot: str
    method: str
    joint_names: list[str]
    duration: float
    samples: SamplesPublic
    phase_plane: PhasePlanePublic
    peak_utilization: UtilizationPublic
    binding: BindingPublic | None = None
    conditioning: ConditioningPublic
    cost: float | None = Field(default=None, description="min_cost, collocation: the integral of (1 + beta |tau|^2) dt, in s.")
    solver: dict | None = Field(default=None, description="collocation: status, iterations, the winning initial guess.")
    solve_ms: float
    warnings: list[str]


class CompareRequest(Schema):
    """One path under several timing methods."""

    robot: Name = Field(description="Catalog or uploaded robot name, e.g. `ur5`.")
    path: PathRequest
    methods: list[Name] = Field(
        min_length=1, max_length=10, description="Timing methods to run, e.g. [\"phase_plane\", \"quintic\"]."
    )
    timing: TimingRequest = TimingRequest()


class CompareResult(BaseModel):
    """One method's answer: its duration, peak utilization and solve time, or its error."""

    method: str
    duration: float | None = None
    peak_utilization: UtilizationPublic | None = None
    binding: BindingPublic | None = None
    solve_ms: float | None = None
    error: dict | None = None


class CompareResponse(BaseModel):
    results: list[CompareResult]
