"""Schemas of the answers of ``POST /v1/trajectories`` and ``POST /v1/trajectories/compare``
(DESIGN.md, HTTP contract); the requests are ``toptraj.service.schemas.trajectories``."""

from __future__ import annotations

from pydantic import BaseModel, Field


class SamplesPublic(BaseModel):
    """Time samples; ``q[k]`` holds one value per joint at ``t[k]``."""

    t: list[float] = Field(description="Sample times (s).")
    q: list[list[float]] = Field(description="Joint positions (rad, m), a row per sample.")
    qd: list[list[float]] = Field(description="Joint velocities (rad/s, m/s), a row per sample.")
    qdd: list[list[float]] = Field(description="Joint accelerations (rad/s^2, m/s^2), a row per sample.")
    tau: list[list[float]] = Field(description="Joint torques (N m) or forces (N) from inverse dynamics with friction, a row per sample.")


class SwitchPoint(BaseModel):
    s: float = Field(description="Path parameter of the switch (0 to 1).")
    kind: str = Field(description="How the switch arises: acceleration, deceleration, tangent, singular, discontinuity.")


class PhasePlanePublic(BaseModel):
    """The timing in the phase plane: path speed ``sd`` and maximum velocity curve ``sd_max``
    (1/s) over s in [0, 1]."""

    s: list[float] = Field(description="Path parameter of each point (0 to 1).")
    sd: list[float] = Field(description="Path speed ds/dt at each point (1/s).")
    sd_max: list[float | None] = Field(description="Maximum velocity curve at each point (1/s); null where unbounded.")
    switch_points: list[SwitchPoint] = Field(default=[], description="Where the path acceleration switches, and the kind of switch.")


class UtilizationPublic(BaseModel):
    """Peak |value| / limit per joint over a dense resampling (1.0: the limit binds), against
    the limit in force at each state (a zone's inside it); jerk for timings with a finite jerk
    (jerk_limited, ruckig, the time laws whose acceleration is continuous: not cubic, trapezoidal
    or a collocation's bang-bang motion, whose jerk is infinite where their acceleration jumps);
    null where a joint has no finite limit of that kind."""

    velocity: list[float | None] = Field(description="Peak |qd| / velocity limit per joint; null for a joint without a finite velocity limit.")
    acceleration: list[float | None] = Field(description="Peak |qdd| / acceleration limit per joint; null for a joint without a finite acceleration limit.")
    torque: list[float | None] = Field(description="Peak |tau| / torque limit per joint; null for a joint without a finite torque limit.")
    jerk: list[float | None] | None = Field(
        default=None, description="Peak |qddd| / jerk limit per joint, for timings with a finite jerk; null for a joint without a finite jerk limit."
    )
    tool_speed: float | None = Field(default=None, description="Peak tool speed / the tool-speed limit in force (timing.limits.tool_speed, or a zone's), when limited.")
    tool_angular_speed: float | None = Field(
        default=None, description="Peak angular tool speed / timing.limits.tool_angular_speed, when limited."
    )


class BindingPublic(BaseModel):
    """The limit that set a minimal duration (time laws): its kind, joint and place."""

    kind: str = Field(description="The binding limit: velocity, acceleration, jerk or torque.")
    joint: str | None = Field(description="The joint whose limit binds; null for a limit of the whole path.")
    s: float = Field(description="Where along the path it binds (path parameter, 0 to 1).")


class ConditioningPublic(BaseModel):
    """Frobenius condition number of the end effector's Jacobian along the trajectory (1:
    isotropic; null: singular), translations over the characteristic length L (m)."""

    kappa_min: float | None = Field(description="Smallest condition number along the trajectory (1: isotropic); null where singular.")
    kappa_max: float | None = Field(description="Largest condition number along the trajectory; null where singular.")
    characteristic_length: float = Field(description="Length (m) that makes translations and rotations commensurate in the Jacobian.")


class TimeFromStart(BaseModel):
    """``builtin_interfaces/Duration``: whole seconds and the nanoseconds within the second."""

    sec: int = Field(description="Whole seconds.")
    nanosec: int = Field(description="Nanoseconds within the second, 0 to 999,999,999.")


class JointTrajectoryPoint(BaseModel):
    """``trajectory_msgs/JointTrajectoryPoint``: one value per joint, SI units (rad, rad/s,
    rad/s^2, N m; m and N for prismatic joints)."""

    positions: list[float] = Field(description="Joint positions (rad, m).")
    velocities: list[float] = Field(description="Joint velocities (rad/s, m/s).")
    accelerations: list[float] = Field(description="Joint accelerations (rad/s^2, m/s^2).")
    effort: list[float] = Field(description="Joint torques (N m) or forces (N).")
    time_from_start: TimeFromStart = Field(description="Time of the point from the start.")


class JointTrajectoryPublic(BaseModel):
    """``trajectory_msgs/JointTrajectory`` without its header (``output.format =
    "joint_trajectory"``)."""

    joint_names: list[str] = Field(description="Joint names, in the order of every point's values.")
    points: list[JointTrajectoryPoint] = Field(description="The samples, one point each, on whole periods of output.dt.")


class ClearancePublic(BaseModel):
    """The closest approach of the robot to the obstacles along the path."""

    distance: float = Field(description="Smallest distance (m) between a link and an obstacle; at least path.clearance.")
    link: str = Field(description="The link (its collision capsule) where it occurs.")
    obstacle: int = Field(description="The obstacle, as its index in path.obstacles.")
    s: float = Field(description="Where along the path (path parameter, 0 to 1).")


class SearchPublic(BaseModel):
    """What the global search did (timing.method `search`; Jeong & Lee section 2)."""

    graph: str = Field(description="`lattice` or `roadmap`.")
    grid_points: int = Field(description="Grid points of the graph (count).")
    grid_edges: int = Field(description="Moves between grid points (count).")
    grid_shape: list[int] = Field(description="Grid points per joint of a lattice; empty for a roadmap.")
    turns: int = Field(description="Edges of the direction-augmented graph: pairs of consecutive moves without a sharp turn (count).")
    removed_by_obstacles: int = Field(description="Pieces of curve (B-spline spans) removed as configuration-space obstacles, among those checked (count; see spans_checked).")
    points_blocked: int = Field(description="Grid points closer to an obstacle than path.clearance (count).")
    spans_checked: int = Field(
        default=0,
        description="Pieces of curve whose clearance was checked (count): all of a lattice's; on a roadmap only those of "
        "the grid paths the search timed (lazy checks, as in Lazy PRM).",
    )
    searches: int = Field(default=1, description="Branch and bounds run: one more after each whose grid paths met a piece of curve found blocked.")
    v_max: float | None = Field(description="V_max of the maximum speed test t1 (joint units/s); null where no limit bounds the speed.")
    expanded: int = Field(description="Partial paths branched (count).")
    generated: int = Field(description="Subsets of grid paths created (count).")
    pruned: dict[str, int] = Field(description="Subsets discarded by each lower bound t1, t2, t3, t4, and by the upper bound t_u (counts).")
    t4_evaluations: int = Field(description="Grid paths timed by the phase-plane method (count).")
    candidates: int = Field(description="Grid paths found within t_u (count).")
    best_grid_time: float | None = Field(description="t~: the best grid path's time (s), on the search's grid.")
    upper_bound: float | None = Field(description="t_u at the end (s).")
    complete: bool = Field(description="Whether the search ended by its bounds (the best grid path is the best of the graph).")
    prepare_s: float = Field(description="Time building the graph, its obstacles and bounds (s).")
    search_s: float = Field(description="Time of the branch and bound (s).")
    tube_radius: float = Field(description="D_max (joint units).")
    tubes: list[dict] = Field(description="The best grid path of each tube, best first: time (s), bounds t1, t2, t3 (s) and points (joint configurations; the curve is the uniform cubic B-spline with these control points).")
    chosen_tube: int = Field(description="The tube whose grid path the answer follows (index into tubes).")
    region: dict = Field(description="The region of joint space searched: lower and upper corners.")
    shadows: dict | None = Field(
        default=None,
        description="Planar two-joint arms among obstacles: the configuration-space occupancy grid (joints, q, occupied) "
        "and the obstacle shadows of the tip per elbow branch (points in the arm's plane, m).",
    )


class AccuracyPublic(BaseModel):
    """How far the answer lies from the converged optimum of its method's problem (the limit
    of the grid's interval going to zero), estimated independently of the solve. A
    time-optimal answer (phase_plane, toppra, min_cost with torque_weight 0, the search's
    timing) above 0.1 % on its default grid is refined until it holds; one that still is, or
    whose grid the request named, says so in `warnings`, with the figure."""

    relative_gap: float | None = Field(
        description="Estimated |objective / converged optimum - 1| (the duration for time-optimal methods, "
        "the cost for min_cost with a torque weight); null when no estimate exists (`basis` says why)."
    )
    basis: str = Field(description="How the estimate was obtained (a second discretization, another method), or why there is none.")


class ZonePublic(BaseModel):
    """Where a zone of timing.zones lies on the path and whether it bound the timing."""

    index: int = Field(description="The zone's place in timing.zones.")
    ranges: list[list[float]] = Field(description="The closed s-ranges [s0, s1] it covers (empty: a region the path never enters).")
    peak: float = Field(description="Largest ratio inside the zone of a quantity it limits to the zone's own limit (1.0: reached; with timing.limit_margin, against the limit as given).")
    binding: bool = Field(description="Whether its limits bound the timing (its peak within 0.5 % of the limits it was planned under).")


class PayloadPublic(BaseModel):
    """The payload the torques include, as applied (the request's, else the upload's default)."""

    mass: float = Field(description="Mass (kg).")
    center_of_mass: list[float] = Field(description="Centre of mass [x, y, z] (m) in `frame`.")
    inertia: list[list[float]] = Field(description="Rotational inertia about the centre of mass in `frame`'s axes (kg m^2), 3x3; zeros for a point mass.")
    frame: str = Field(description="The frame holding it.")
    radius: float = Field(description="Radius (m) of its collision sphere about the centre of mass (0: it does not collide).")
    units: dict[str, str] = Field(description="The unit of each quantity.")


class MountingPublic(BaseModel):
    """The base pose in the world and the gravity the torques follow, as applied."""

    position: list[float] = Field(description="The base frame's origin in the world (m).")
    rotation: list[list[float]] = Field(description="Rotation from the base's axes to the world's, 3x3 (rows).")
    gravity: list[float] = Field(description="Gravity in the world (m/s^2).")
    units: dict[str, str] = Field(description="The unit of each quantity.")


class TrajectoryResponse(BaseModel):
    """A timed joint trajectory with its torques."""

    robot: str = Field(description="The robot planned for.")
    method: str = Field(description="The timing method used.")
    joint_names: list[str] = Field(description="Joint names, in the order of every per-joint list.")
    duration: float = Field(description="Planned duration (s).")
    sampled_duration: float = Field(
        description="Time of the last sample (s): `duration`, or with `output.exact_period` the whole periods it was stretched to."
    )
    samples: SamplesPublic | None = Field(default=None, description="`output.format = \"samples\"`: t (s), q, qd, qdd, tau per sample.")
    joint_trajectory: JointTrajectoryPublic | None = Field(default=None, description="`output.format = \"joint_trajectory\"`: the samples as ROS's trajectory_msgs/JointTrajectory.")
    phase_plane: PhasePlanePublic = Field(description="The timing in the phase plane (s, path speed, maximum velocity curve).")
    peak_utilization: UtilizationPublic = Field(description="Peak |value| / limit per joint on a dense resampling (1.0: the limit binds).")
    binding: BindingPublic | None = Field(default=None, description="The limit that set a minimal duration (time laws).")
    conditioning: ConditioningPublic = Field(description="Condition number of the end effector's Jacobian along the trajectory.")
    cost: float | None = Field(default=None, description="min_cost, collocation: the integral of (1 + beta |tau|^2) dt, in s.")
    solver: dict | None = Field(default=None, description="collocation: status, iterations, the winning initial guess.")
    switching_times: dict[str, list[float]] | None = Field(
        default=None,
        description="collocation with torque_weight 0 (bang-bang torques): for each joint name, the times (s) "
        "at which its saturated torque changes sides, in increasing order; solver.switching says whether "
        "they were refined (exact bang-bang controls) or read off the samples.",
    )
    solve_ms: float = Field(description="Time spent planning (ms), without reading the request nor writing the answer.")
    min_clearance: ClearancePublic | None = Field(
        default=None, description="With path.obstacles: the closest approach of any link to any obstacle."
    )
    search: SearchPublic | None = Field(default=None, description="timing.method `search`: what the global search did.")
    warnings: list[str] = Field(description="What the answer should be read with: dropped waypoints, singularities, turns of continuous joints, an accuracy above 0.1 %.")
    accuracy: AccuracyPublic = Field(description="The answer's estimated relative distance from the converged optimum of its method's problem.")
    zones: list[ZonePublic] | None = Field(default=None, description="With timing.zones: where each lies on the path and whether it bound the timing.")
    payload: PayloadPublic | None = Field(default=None, description="The payload the torques include (null: none).")
    mounting: MountingPublic | None = Field(default=None, description="With `mounting`: the base pose and the world's gravity applied (null: the model's own base and gravity).")


class CompareResult(BaseModel):
    """One method's answer: its duration, peak utilization and solve time, or its error."""

    method: str = Field(description="The timing method.")
    duration: float | None = Field(default=None, description="Duration (s); null when the method failed.")
    peak_utilization: UtilizationPublic | None = Field(default=None, description="Peak |value| / limit per joint on a dense resampling.")
    binding: BindingPublic | None = Field(default=None, description="The limit that set a minimal duration (time laws).")
    solve_ms: float | None = Field(default=None, description="Planning time (ms).")
    error: dict | None = Field(default=None, description="The method's problem (status, title, detail) when it failed.")
    accuracy: AccuracyPublic | None = Field(default=None, description="The answer's estimated distance from its method's converged optimum; null when the method failed.")
    warnings: list[str] | None = Field(default=None, description="What the answer should be read with (an accuracy above 0.1 % among them); null when the method failed.")


class CompareResponse(BaseModel):
    results: list[CompareResult] = Field(description="One result per requested method, in the order asked.")
