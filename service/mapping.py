"""The request's words mapped into the library's own objects: the method object with its
options (a timing method, or the motion generator that shapes the motion with it), the motion
(waypoints, a Cartesian line, a free motion), the limits asked for, the boundary states, the
obstacles and zones; ``problem_of`` builds the ``Problem`` from them
(``toptraj.planners.problem.build.build_problem``). The rules of a request's shape (an option
sent to a method that takes none) are checked here; the rules among one option object's fields
are its constructor's."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj import robots
from toptraj.planners import CartesianLine, WaypointPath
from toptraj.planners.collision import BoxObstacle, CapsuleObstacle, Obstacle, SphereObstacle
from toptraj.planners.errors import NotOneOf, NotServed, WrongLength
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.generators.joint_moves import Unsynchronized, ViaPoints
from toptraj.planners.problem.boundary import finite_vector
from toptraj.planners.problem.build import DEFAULT_CLEARANCE, build_problem
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import MotionGenerator
from toptraj.planners.problem.problem import BoundaryStates, LimitRequest, MotionSpec, Problem, Sampling
from toptraj.planners.problem.time_law import TimeLaw
from toptraj.planners.problem.zones import Zone
from toptraj.planners.timing import METHODS
from toptraj.planners.timing.base import TimingMethod
from toptraj.planners.timing.laws.profiles import PROFILES
from toptraj.service.schemas.trajectories import TimingRequest, TrajectoryRequest

if TYPE_CHECKING:
    from toptraj.planners.generators.search import SearchOptions

#: Limit kinds a request may override or scale.
LIMIT_KINDS = ("velocity", "acceleration", "jerk", "torque")
#: Methods that take a torque weight.
WEIGHTED = ("min_cost", "collocation")


def problem_of(
    request: TrajectoryRequest, robot: robots.Robot, deadline: Deadline, max_samples: int, exact_period: bool,
    search_memory_bytes: int,
) -> Problem:
    """The validated problem of ``request`` for ``robot`` (its payload and mounting applied),
    sampled into at most ``max_samples`` samples, a search within ``search_memory_bytes``."""
    timing, path = request.timing, request.path
    motion = motion_of(path, robot, timing)
    return build_problem(
        robot, motion, method_of(timing, motion, search_memory_bytes),
        limits=limit_request(timing), boundary=boundary_states(timing, isinstance(motion, FreeMotion)),
        duration=timing.duration, grid=timing.grid_points,
        sampling=Sampling(request.output.dt, max_samples, exact_period),
        obstacles=obstacles_of(getattr(path, "obstacles", [])), clearance=getattr(path, "clearance", DEFAULT_CLEARANCE),
        deadline=deadline, self_collision=getattr(path, "self_collision", False),
    )


def method_of(timing: TimingRequest, motion: MotionSpec, search_memory_bytes: int) -> TimingMethod | MotionGenerator:
    """The method object ``timing.method`` names, holding its options; a time law through via
    points or joint by joint becomes the generator that shapes the motion with it. A free motion
    with a timing method stays a timing method (``build_problem`` refuses the pair)."""
    name, weight = timing.method, timing.cost.torque_weight
    law = None
    if name in PROFILES or timing.trapezoid.blend != "linear" or timing.supporting_points is not None:
        law = TimeLaw(name, (timing.trapezoid.tau1, timing.trapezoid.tau2), timing.trapezoid.blend, timing.supporting_points)
    if weight != 0.0 and name not in WEIGHTED:
        raise NotServed("method.torque_weight", weight, name, rule="weight_needs_min_cost", alternatives=("min_cost",))
    if timing.search is not None and name not in ("search", "collocation"):
        raise NotServed("search", None, name, rule="options_need_search", alternatives=("search",))
    # The search, the collocation and min_cost are imported where they are named: the other
    # requests do without their modules, solver stacks and compiled kernels.
    if name == "search":
        from toptraj.planners.generators.search.generator import Search

        return Search(search_options(timing, search_memory_bytes))
    if name == "collocation":
        from toptraj.planners.generators.collocation.generator import Collocation

        return Collocation(weight)
    method: TimingMethod
    if law is not None:
        method = law.method()
    elif name == "min_cost":
        from toptraj.planners.timing.min_cost import MinCostMethod

        method = MinCostMethod(weight)
    elif name in METHODS:
        method = METHODS[name]
    else:
        raise NotOneOf("method", name, sorted([*METHODS, "collocation", "search"]))
    if isinstance(motion, FreeMotion):
        return method
    if timing.synchronization == "none":
        return Unsynchronized(method)
    if isinstance(motion, WaypointPath) and motion.interpolation == "via":
        return ViaPoints(method)
    return method


def search_options(timing: TimingRequest, memory_bytes: int) -> SearchOptions:
    """The search's options (``toptraj.planners.generators.search.SearchOptions``), held within
    ``memory_bytes`` by its estimate."""
    from toptraj.planners.generators.search import SearchOptions

    if timing.search is None:
        return SearchOptions(memory_bytes=memory_bytes)
    cells = None if timing.search.cells is None else tuple(timing.search.cells)
    return SearchOptions(cells=cells, memory_bytes=memory_bytes, **timing.search.model_dump(exclude={"cells"}))


def limit_request(timing: TimingRequest) -> LimitRequest:
    """The limits ``timing`` asks for: kinds, overrides and scales, margin, tool limits, zones."""
    limits = timing.limits
    return LimitRequest(
        kinds=None if timing.constraints is None else tuple(timing.constraints),
        overrides={kind: getattr(limits, kind) for kind in LIMIT_KINDS},
        scales={kind: getattr(limits, f"{kind}_scale") for kind in LIMIT_KINDS},
        margin=timing.limit_margin,
        tool_speed=limits.tool_speed,
        tool_angular_speed=limits.tool_angular_speed,
        tool_frame=limits.tool_frame,
        zones=tuple(_zone(spec) for spec in timing.zones),
    )


def boundary_states(timing: TimingRequest, free: bool) -> BoundaryStates:
    """The boundary states of ``timing.boundary``; a free motion carries its velocities itself."""
    boundary = timing.boundary
    return BoundaryStates(
        start_velocity=None if free else boundary.start_velocity,
        end_velocity=None if free else boundary.end_velocity,
        start_acceleration=boundary.start_acceleration,
        end_acceleration=boundary.end_acceleration,
    )


def _zone(spec) -> Zone:
    """A zone of ``timing.zones`` as the library's ``Zone``."""
    region: SphereObstacle | BoxObstacle | None = None
    if spec.sphere is not None:
        region = SphereObstacle(np.array(spec.sphere.center, dtype=float), spec.sphere.radius)
    elif spec.box is not None:
        region = BoxObstacle(np.array(spec.box.center, dtype=float), np.array(spec.box.size, dtype=float), np.array(spec.box.orientation, dtype=float))
    return Zone(
        s_range=None if spec.s_range is None else (spec.s_range[0], spec.s_range[1]),
        region=region,
        velocity=spec.velocity_scale,
        acceleration=spec.acceleration_scale,
        torque=spec.torque_scale,
        tool_speed=spec.tool_speed,
    )


def obstacles_of(specs) -> tuple[Obstacle, ...]:
    """The request's obstacles as the library's domain objects."""
    made: list[Obstacle] = []
    for spec in specs:
        if spec.kind == "sphere":
            made.append(SphereObstacle(np.array(spec.center, dtype=float), spec.radius))
        elif spec.kind == "box":
            made.append(BoxObstacle(np.array(spec.center, dtype=float), np.array(spec.size, dtype=float), np.array(spec.orientation, dtype=float)))
        else:
            made.append(CapsuleObstacle(np.array(spec.a, dtype=float), np.array(spec.b, dtype=float), spec.radius))
    return tuple(made)


def motion_of(spec, robot: robots.Robot, timing: TimingRequest) -> MotionSpec:
    """The request's path as the library's motion: joint waypoints, a Cartesian line, or a free
    motion from a start to a goal (with ``timing.boundary``'s velocities)."""
    if spec.kind == "free":
        for name in ("start", "goal"):
            if len(getattr(spec, name)) != robot.dof:
                raise WrongLength(name, getattr(spec, name), len(getattr(spec, name)), robot.dof, robot=robot.name)
        boundary = timing.boundary

        def velocity(name):
            value = getattr(boundary, name)
            return None if value is None else finite_vector(value, f"boundary.{name}", robot.dof)

        return FreeMotion(
            start=np.asarray(spec.start, dtype=float),
            goal=np.asarray(spec.goal, dtype=float),
            start_velocity=velocity("start_velocity"),
            end_velocity=velocity("end_velocity"),
            revolutions=spec.revolutions,
        )
    if spec.kind == "cartesian":
        if len(spec.start) != robot.dof:
            raise WrongLength("start", spec.start, len(spec.start), robot.dof, robot=robot.name)
        return CartesianLine(
            start=np.asarray(spec.start, dtype=float),
            positions=None if spec.positions is None else np.asarray(spec.positions, dtype=float),
            poses=None if spec.poses is None else np.asarray(spec.poses, dtype=float),
            frame=spec.frame,
        )
    for index, row in enumerate(spec.waypoints):
        if len(row) != robot.dof:
            raise WrongLength(f"waypoints[{index}]", row, len(row), robot.dof, robot=robot.name, joint_names=robot.joint_names)
    return WaypointPath(np.asarray(spec.waypoints, dtype=float), spec.interpolation, spec.max_deviation, spec.continuous, spec.min_spacing)
