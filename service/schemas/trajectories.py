"""Schemas of the requests of ``POST /v1/trajectories`` and ``POST /v1/trajectories/compare``
(DESIGN.md, HTTP contract); the answers are ``toptraj.service.schemas.answers``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeVar

from pydantic import Discriminator, Field, Tag, field_validator, model_validator

from toptraj.planners.checks.gate import PROMISED_TOLERANCE
from toptraj.planners.problem import ranges
from toptraj.planners.problem.requests import DEFAULT_MIN_SPACING
from toptraj.planners.timing import METHODS
from toptraj.planners.timing.laws.splines import MAX_SUPPORTING_POINTS, MIN_SUPPORTING_POINTS
from toptraj.service.schemas.common import Schema, bounded, signed
from toptraj.service.schemas.compare_rules import each_method_once, timing_method_among_methods
from toptraj.service.schemas.equipment import MOUNTING, PAYLOAD, MountingRequest, PayloadRequest
from toptraj.service.schemas.obstacles import CLEARANCE, MAX_OBSTACLES, OBSTACLES, SELF_COLLISION, ObstacleRequest
from toptraj.service.schemas.zones import ZONES, ZoneRequest

MAX_WAYPOINTS = 1_000
MAX_JOINTS = 64
#: Longest robot, frame or method name accepted (names are echoed in error messages).
MAX_NAME_CHARS = 256


_Item = TypeVar("_Item")
#: A list of one value per joint: ``PerJoint[Annotated[float, bounded(ranges.VELOCITY)]]``.
PerJoint = Annotated[list[_Item], Field(min_length=1, max_length=MAX_JOINTS)]
Coordinate = Annotated[float, signed(ranges.COORDINATE)]
JointVector = PerJoint[Coordinate]
Name = Annotated[str, Field(max_length=MAX_NAME_CHARS)]


class WaypointsPath(Schema):
    """Joint waypoints, interpolated by a C2 cubic spline, by straight segments that stop at
    each waypoint, or by straight segments joined by circular blends."""

    kind: Literal["waypoints"] = Field(default="waypoints", description="`waypoints` (the default when left out).")
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
    max_deviation: Annotated[float, bounded(ranges.MAX_DEVIATION)] | None = Field(
        default=None,
        description="`blend` only: largest joint-space distance (Euclidean norm, rad or m) of a blend from "
        "its waypoint; default 0.1.",
    )
    continuous: Literal["as_given", "shortest"] = Field(
        default="as_given",
        description="Continuous joints (no position limits): `as_given` follows the numbers (a warning "
        "when one turns more than pi between waypoints), `shortest` turns the short way, waypoints "
        "after the first reached as equivalent angles.",
    )
    min_spacing: Annotated[float, bounded(ranges.MIN_SPACING)] | None = Field(
        default=None,
        description="A waypoint within this share of the path's joint-space length of the waypoint kept before it "
        "is dropped as a repeat, with a warning (one so near the last, in the last's place): a spline or blend "
        f"through waypoints so near turns sharply and the arm nearly stops there. Default {DEFAULT_MIN_SPACING:g} "
        "for `spline` and `blend`, 0 for `linear` and `via`; 0 keeps every waypoint that differs.",
    )
    obstacles: list[ObstacleRequest] = OBSTACLES
    clearance: float = CLEARANCE
    self_collision: bool = SELF_COLLISION


class CartesianPathRequest(Schema):
    """Straight lines of a frame through positions (orientation free) or poses (orientation by
    slerp), from the pose of the start configuration; joint path by inverse kinematics."""

    kind: Literal["cartesian"] = Field(description="`cartesian`: straight lines of a frame, joints by inverse kinematics.")
    frame: Name | None = Field(default=None, description="Frame to move; default the robot's end effector.")
    start: JointVector = Field(description="Start joint configuration (rad, m).")
    positions: list[Annotated[list[float], Field(min_length=3, max_length=3)]] | None = Field(
        default=None, min_length=1, max_length=MAX_WAYPOINTS, description="[x, y, z] in m, world frame."
    )
    poses: list[Annotated[list[float], Field(min_length=7, max_length=7)]] | None = Field(
        default=None, min_length=1, max_length=MAX_WAYPOINTS, description="[x, y, z, qx, qy, qz, qw]."
    )
    obstacles: list[ObstacleRequest] = OBSTACLES
    clearance: float = CLEARANCE
    self_collision: bool = SELF_COLLISION


class FreePathRequest(Schema):
    """Start and goal only: the path and its timing are optimized together (timing.method
    `collocation`), or searched globally among obstacles (timing.method `search`)."""

    kind: Literal["free"] = Field(description="`free`: start and goal only (timing.method `collocation` or `search`).")
    start: JointVector = Field(description="Start configuration (rad, m), at rest unless timing.boundary says otherwise.")
    goal: JointVector = Field(description="Goal configuration (rad, m).")
    revolutions: bool = Field(
        default=True, description="Whether continuous joints may reach their goal one revolution either way."
    )
    obstacles: list[ObstacleRequest] = Field(
        default=[],
        max_length=MAX_OBSTACLES,
        description="Obstacles in the world frame (spheres, boxes, capsules), with timing.method `search`: every "
        "link keeps path.clearance from them along the motion found; the answer reports min_clearance.",
    )
    clearance: float = CLEARANCE
    self_collision: bool = SELF_COLLISION


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
#: The OpenAPI discriminator of ``path``: ``kind`` chooses the schema (left out, it is
#: ``waypoints``, which the validator above applies).
PATH_DISCRIMINATOR: dict[str, Any] = {
    "propertyName": "kind",
    "mapping": {
        "waypoints": "#/components/schemas/WaypointsPath",
        "cartesian": "#/components/schemas/CartesianPathRequest",
        "free": "#/components/schemas/FreePathRequest",
    },
}


class LimitsRequest(Schema):
    """Per-joint overrides and scale factors of the robot's limits, and limits on the speed of a
    tool frame (SI units)."""

    velocity: PerJoint[Annotated[float, bounded(ranges.VELOCITY)]] | None = Field(default=None, description="Per-joint velocity limits replacing the robot's (rad/s, m/s).")
    acceleration: PerJoint[Annotated[float, bounded(ranges.ACCELERATION)]] | None = Field(default=None, description="Per-joint acceleration limits replacing the robot's (rad/s^2, m/s^2).")
    jerk: PerJoint[Annotated[float, bounded(ranges.JERK)]] | None = Field(default=None, description="Per-joint jerk limits replacing the robot's (rad/s^3, m/s^3).")
    torque: PerJoint[Annotated[float, bounded(ranges.TORQUE)]] | None = Field(default=None, description="Per-joint torque limits replacing the robot's (N m, N).")
    velocity_scale: Annotated[float, bounded(ranges.SCALE)] | None = Field(default=None, description="Factor on every velocity limit (after overrides); each scaled limit lies in the range of its kind, as an override does.")
    acceleration_scale: Annotated[float, bounded(ranges.SCALE)] | None = Field(default=None, description="Factor on every acceleration limit; each scaled limit lies in the range of its kind, as an override does.")
    jerk_scale: Annotated[float, bounded(ranges.SCALE)] | None = Field(default=None, description="Factor on every jerk limit; each scaled limit lies in the range of its kind, as an override does.")
    torque_scale: Annotated[float, bounded(ranges.SCALE)] | None = Field(default=None, description="Factor on every torque limit; each scaled limit lies in the range of its kind, as an override does.")
    tool_speed: Annotated[float, bounded(ranges.TOOL_SPEED)] | None = Field(
        default=None, description="Largest linear speed of the tool frame's origin (m/s)."
    )
    tool_angular_speed: Annotated[float, bounded(ranges.TOOL_ANGULAR_SPEED)] | None = Field(
        default=None, description="Largest angular speed of the tool frame (rad/s)."
    )
    tool_frame: Name | None = Field(
        default=None, description="Frame whose speed tool_speed and tool_angular_speed limit; default the robot's end effector."
    )


class Boundary(Schema):
    """Joint velocities (rad/s) and accelerations (rad/s^2) at the ends, tangent to the path;
    absent means rest."""

    start_velocity: PerJoint[Annotated[float, signed(ranges.VELOCITY)]] | None = Field(default=None, description="Joint velocities at the start (rad/s, m/s), tangent to the path.")
    end_velocity: PerJoint[Annotated[float, signed(ranges.VELOCITY)]] | None = Field(default=None, description="Joint velocities at the end (rad/s, m/s), tangent to the path.")
    start_acceleration: PerJoint[Annotated[float, signed(ranges.ACCELERATION)]] | None = Field(default=None, description="Joint accelerations at the start (rad/s^2, m/s^2).")
    end_acceleration: PerJoint[Annotated[float, signed(ranges.ACCELERATION)]] | None = Field(default=None, description="Joint accelerations at the end (rad/s^2, m/s^2).")


class CostRequest(Schema):
    """Weights of the cost integral of (1 + beta |tau|^2) dt (min_cost): beta in 1/(N m)^2."""

    torque_weight: Annotated[float, Field(description="beta of the cost integral of (1 + beta |tau|^2) dt, in 1/(N m)^2 (min_cost, collocation).", ge=0.0, le=1e3)] = 0.0


class TrapezoidRequest(Schema):
    """Switching fractions of the trapezoidal law (Angeles 6.1): acceleration ends at tau1 and
    deceleration starts at tau2, as fractions of the duration."""

    tau1: Annotated[float, bounded(ranges.TRAPEZOID_FRACTION)] = Field(default=1.0 / 3.0, description="End of the acceleration phase, as a fraction of the duration.")
    tau2: Annotated[float, bounded(ranges.TRAPEZOID_FRACTION)] = Field(default=2.0 / 3.0, description="Start of the deceleration phase, as a fraction of the duration.")
    blend: Literal["linear", "cycloidal"] = Field(
        default="linear",
        description="Shape of the speed ramps: `linear` (constant acceleration, Angeles 6.1) or "
        "`cycloidal` (half cycloidal motions, continuous acceleration, Angeles 6.3).",
    )


#: Every timing method, as the OpenAPI enum of ``timing.method`` and the compare's ``methods``.
if TYPE_CHECKING:  # the names are known when the methods are imported
    MethodName = str
else:
    MethodName = Literal[(*METHODS, "collocation", "search")]


class SearchRequest(Schema):
    """Options of the global search (timing.method `search`, Jeong & Lee section 2): the grid of
    joint space, the turns allowed, the upper bound's margin and the tubes."""

    cells: Annotated[list[Annotated[int, Field(ge=1, le=1000)]], Field(min_length=1, max_length=MAX_JOINTS)] | None = Field(
        default=None,
        description="Grid intervals per joint across the search region (one value for every joint, or one per "
        "joint); the step is then adjusted so that the goal lies on the grid. Default: 16 per joint for two "
        "joints, 8 for three; arms with more joints search a roadmap.",
    )
    margin: Annotated[float, Field(ge=0.0, le=10.0)] = Field(
        default=0.5,
        description="How far the search region reaches beyond the box of start and goal along every joint, as "
        "a multiple of the largest joint span from start to goal (within the joint limits).",
    )
    max_turn: Annotated[float, Field(gt=0.0, lt=180.0)] | None = Field(
        default=None,
        description="Largest turn between consecutive moves (degrees, in grid units); sharper turns are not "
        "searched. Default: 45 on a lattice, 90 on a roadmap.",
    )
    upper_margin: Annotated[float, Field(ge=0.0, le=10.0)] = Field(
        default=0.02,
        description="epsilon of the upper bound t_u = (1 + epsilon) t~ (relative): grid paths within it of the "
        "best are kept as candidates, one per tube.",
    )
    tube_radius: Annotated[float, Field(gt=0.0, le=100.0)] | None = Field(
        default=None,
        description="D_max (rad or m): grid paths within this joint-space (Hausdorff) distance of a better "
        "one belong to its tube. Default: three grid steps.",
    )
    tubes: Annotated[int, Field(ge=1, le=20)] = Field(default=3, description="Most tubes (best grid paths of distinct regions) kept.")
    graph: Literal["auto", "lattice", "roadmap"] = Field(
        default="auto",
        description="`lattice`: grid points joined to their 3^n - 1 neighbours; `roadmap`: seeded random "
        "configurations joined to their nearest neighbours (for arms with many joints); `auto`: a lattice up "
        "to three joints.",
    )
    roadmap_points: Annotated[int, Field(ge=1, le=2000)] = Field(default=150, description="Random configurations of a roadmap (count).")
    neighbors: Annotated[int, Field(ge=1, le=50)] = Field(default=10, description="Nearest neighbours each roadmap point is joined to (count).")
    seed: Annotated[int, Field(ge=0, le=2**31 - 1)] = Field(default=0, description="Seed of the roadmap's random configurations.")
    max_expansions: Annotated[int, Field(ge=1, le=5_000_000)] = Field(
        default=200_000, description="Most partial paths the branch and bound expands (count)."
    )


class TimingRequest(Schema):
    """How to time the path."""

    method: MethodName = Field(
        default="phase_plane",
        description="`phase_plane` (time-optimal, default), `toppra`, `min_cost` (minimum of the "
        "integral of 1 + beta |tau|^2), `jerk_limited` (time-optimal with jerk limits too), `ruckig` "
        "(jerk-limited, two waypoints), a time law "
        "(`cubic`, `quintic`, `trapezoidal`, `cycloidal`), or on a free path `collocation` or `search` (global "
        "search among obstacles).",
    )
    constraints: list[Literal["velocity", "acceleration", "torque", "jerk"]] | None = Field(
        default=None,
        max_length=4,
        description="Limits to respect; jerk only with jerk_limited, the time laws and ruckig. Left out: "
        "velocity, acceleration and torque, those of them the method holds (a warning names any it cannot hold).",
    )
    limits: LimitsRequest = Field(default=LimitsRequest(), description="Limit overrides and scale factors, and tool-speed limits.")
    duration: Annotated[float, bounded(ranges.DURATION)] | None = Field(
        default=None, description="Seconds, for the classical time laws and via points."
    )
    boundary: Boundary = Field(default=Boundary(), description="Joint velocities and accelerations at the ends; rest by default.")
    cost: CostRequest = Field(default=CostRequest(), description="Weights of the cost integral (min_cost, collocation).")
    trapezoid: TrapezoidRequest = Field(default=TrapezoidRequest(), description="Switching fractions of the trapezoidal law.")
    grid_points: Annotated[int, Field(ge=2, le=20_000)] | None = Field(
        default=None, description="Number of grid intervals over the path; default chosen from it."
    )
    supporting_points: Annotated[int, Field(ge=MIN_SUPPORTING_POINTS, le=MAX_SUPPORTING_POINTS)] | None = Field(
        default=None,
        description="For a time law: replace it by the cubic spline through this many equally spaced "
        "points of it (count; Angeles 6.1 (c)), at rest at both ends: continuous acceleration and a "
        "finite jerk. Default: the law itself.",
    )
    synchronization: Literal["normalized", "none"] = Field(
        default="normalized",
        description="For a time law on a straight joint move (two waypoints): `normalized` (default) "
        "times the straight joint line as one, all joints starting and stopping together; `none` runs "
        "every joint at its own full speed to its goal, so faster joints finish early and the joint "
        "path is no longer straight (lecture \"Trajectory Planning\").",
    )
    search: SearchRequest | None = Field(
        default=None, description="Options of the global search (timing.method `search`); defaults when left out."
    )
    limit_margin: Annotated[float, Field(ge=0.0, le=0.5)] = Field(
        default=0.0,
        description="Fraction of every velocity, acceleration, jerk and torque limit kept in reserve: "
        "the motion is planned under the limits times (1 - margin). With a positive margin no returned "
        f"sample exceeds any limit; with 0, no limit is exceeded by more than {(PROMISED_TOLERANCE - 1.0) * 100:g} % "
        "on a dense resampling.",
    )
    zones: list[ZoneRequest] = ZONES


class OutputRequest(Schema):
    """Sampling and shape of the returned trajectory."""

    dt: Annotated[float, bounded(ranges.DT)] = Field(default=0.01, description="Sample period (s).")
    format: Literal["samples", "joint_trajectory", "csv"] = Field(
        default="samples",
        description=(
            "`samples`: arrays t, q, qd, qdd, tau; `joint_trajectory`: ROS's "
            "trajectory_msgs/JointTrajectory as JSON (joint_names, points with positions, "
            "velocities, accelerations, effort, time_from_start {sec, nanosec}); `csv`: text/csv, "
            "a header, then the answer's robot, method, durations, peak utilization, binding limit and "
            "warnings as `# key: value` lines, then a row per sample (also chosen by `Accept: text/csv`; "
            "read it with pandas' `read_csv(f, comment=\"#\")` or numpy's `loadtxt(f, delimiter=\",\", skiprows=1)`)."
        ),
    )
    exact_period: bool | None = Field(
        default=None,
        description=(
            "Samples on whole periods `dt`, the final state included: the motion is slowed "
            "uniformly (by less than one period) to end on a sample; `duration` stays the planned "
            "one, `sampled_duration` is the last sample's time. Default: true for "
            "`joint_trajectory` and `csv`, false for `samples` (samples every dt plus the final "
            "instant). Needs a motion from and to rest."
        ),
    )


class TrajectoryRequest(Schema):
    """A motion to plan."""

    robot: Name = Field(description="Catalog or uploaded robot name, e.g. `ur5`.")
    payload: PayloadRequest | None = PAYLOAD
    mounting: MountingRequest | None = MOUNTING
    path: PathRequest = Field(
        description="The geometric path: waypoints, a Cartesian line, or a free start and goal; `kind` says which.",
        json_schema_extra={"discriminator": PATH_DISCRIMINATOR},
    )
    timing: TimingRequest = Field(default=TimingRequest(), description="How to time the path: method, constraints, limits.")
    output: OutputRequest = Field(default=OutputRequest(), description="Sampling and shape of the answer.")


class CompareRequest(Schema):
    """One path under several timing methods."""

    robot: Name = Field(description="Catalog or uploaded robot name, e.g. `ur5`.")
    payload: PayloadRequest | None = PAYLOAD
    mounting: MountingRequest | None = MOUNTING
    path: PathRequest = Field(
        description="The path, as in POST /v1/trajectories.", json_schema_extra={"discriminator": PATH_DISCRIMINATOR}
    )
    methods: list[MethodName] = Field(
        min_length=1, max_length=10, description="Timing methods to run, e.g. [\"phase_plane\", \"quintic\"]."
    )
    timing: TimingRequest = Field(
        default=TimingRequest(), description="Constraints and limits shared by every method (its `method`, if given, must be among `methods`)."
    )

    check_each_method_once = field_validator("methods")(each_method_once)
    check_timing_method = model_validator(mode="after")(timing_method_among_methods)
