"""The bridge between the HTTP schemas and ``toptraj.planners.plan``: request -> library call ->
response body, encoded to JSON bytes by the planning (in a planning thread, or on the event
loop under a short leash for a small request: ``worth_a_leash``)."""

from __future__ import annotations

import math

import numpy as np
import orjson

from toptraj import robots
from toptraj.planners import Deadline, PlannedTrajectory, plan
from toptraj.planners.errors import InfeasiblePath, InvalidRequest, OverMemory, ShareSpent, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE
from toptraj.planners.execution.memory import DEFAULT_SEARCH_MEMORY, MAX_SAMPLES
from toptraj.planners.plan import check
from toptraj.robots import InvalidLimits, UnknownRobot
from toptraj.robots.catalog import catalog_robot_built
from toptraj.service.equipping import equipment_body, equipped_robot, payload_named
from toptraj.service.formats import CSV_MEDIA_TYPE, chosen_format, csv_bytes, exact_period_for, joint_trajectory
from toptraj.service.mapping import problem_of
from toptraj.service.problems import detail, non_finite_answer, note_text, status_of, title_of
from toptraj.service.reports import search_body, solver_body, switching_body
from toptraj.service.schemas.trajectories import CompareRequest, OutputRequest, TrajectoryRequest, WaypointsPath

#: Longest JSON number written (``-1.2345678901234567e-300``) with its separator, in bytes.
NUMBER_BYTES = 25
#: Bytes a ``joint_trajectory`` point adds to its numbers: its keys, braces and the two
#: integers of ``time_from_start``.
POINT_KEYS_BYTES = 160
#: Bytes of a trajectory body set aside for everything but the samples (phase plane of at
#: most 2,000 points, utilization, conditioning, warnings).
RESERVED_BYTES = 256_000


#: Timing methods whose requests may be tried on the event loop first: they check their
#: deadline between short steps and do not size their work by it. Not ``toppra``, whose solve
#: (toppra's own, 20 to 70 ms on 8 ur5 waypoints) checks none: a try would run it whole.
LEASHED_METHODS = frozenset({"phase_plane", "cubic", "quintic", "trapezoidal", "cycloidal"})
#: Most waypoints of a request tried on the event loop first: the typical request (4 on ur5)
#: plans in 3 to 6 ms, ten waypoints in 9 to 14 ms, thirty in about 30 ms.
LEASHED_WAYPOINTS = 8


def worth_a_leash(request: TrajectoryRequest) -> bool:
    """Whether ``request`` is small enough to be tried on the event loop first
    (``PlanningWorkers.run``): a few waypoints without obstacles nor via points, a built
    catalog robot, a method of ``LEASHED_METHODS`` on the default grid or a small one.
    Anything else would mostly slip the leash, and the try would be time lost."""
    path, timing = request.path, request.timing
    return (
        isinstance(path, WaypointsPath)
        and len(path.waypoints) <= LEASHED_WAYPOINTS
        and path.interpolation != "via"  # each segment timed by bisection: 0.5 s on 8 ur5 waypoints
        and not path.obstacles
        and timing.method in LEASHED_METHODS
        and (timing.grid_points or 0) <= 1_000
        and catalog_robot_built(request.robot)
    )


#: Timing methods whose plannings are heavy whatever their size (``heavy``).
HEAVY_METHODS = frozenset({"search", "collocation", "jerk_limited"})
#: Grid intervals from which a min_cost planning is heavy (its default grid is larger): about
#: 0.7 s on 4 ur5 waypoints at 200 intervals, 1.3 s at its default grid, 2 s at 1,000.
HEAVY_MIN_COST_POINTS = 100


def heavy(method: str, path_kind: str, grid_points: int | None) -> bool:
    """Whether a planning is heavy: it takes seconds of CPU and up to a gigabyte (a search, a
    collocation or any free path, jerk_limited's linear programs, min_cost's convex program on
    more than ``HEAVY_MIN_COST_POINTS`` intervals or on its default grid). Heavy plannings are
    admitted apart from the others (``toptraj.service.workers``: ``plan_heavy_workers`` at once per
    process, ``plan_heavy_queue`` waiting), so that the short requests keep their threads and
    their latency while heavy ones run."""
    if method in HEAVY_METHODS or path_kind == "free":
        return True
    return method == "min_cost" and (grid_points is None or grid_points > HEAVY_MIN_COST_POINTS)


def heavy_request(request: TrajectoryRequest | CompareRequest) -> bool:
    """``heavy`` for a trajectory request, or for any method of a comparison."""
    methods = request.methods if isinstance(request, CompareRequest) else [request.timing.method]
    return any(heavy(method, request.path.kind, request.timing.grid_points) for method in methods)


def samples_within(body_bytes: int, n_dof: int, format_: str = "samples") -> int:
    """The most time samples a trajectory body of at most ``body_bytes`` bytes can hold for a
    robot with ``n_dof`` joints: each sample is t and a row of q, qd, qdd and tau, every number
    counted at its longest (``NUMBER_BYTES``), after ``RESERVED_BYTES`` for the rest."""
    per_sample = NUMBER_BYTES * (1 + 4 * n_dof) + 4 * 3  # and each row's brackets and comma
    if format_ == "joint_trajectory":  # a point's keys and its time_from_start
        per_sample += POINT_KEYS_BYTES
    return max(2, (body_bytes - RESERVED_BYTES) // per_sample)


def plan_request(
    request: TrajectoryRequest,
    deadline: Deadline | None = None,
    max_body_bytes: int | None = None,
    accept: str | None = None,
    search_memory_bytes: int = DEFAULT_SEARCH_MEMORY,
) -> PlannedTrajectory:
    """Plan ``request`` with the library (no HTTP involved); with ``max_body_bytes``, refuse an
    ``output.dt`` whose samples would not fit in a body of that size (422 naming the smallest
    ``dt`` that fits). ``accept`` (the HTTP Accept header) may choose CSV, which puts the samples
    on whole periods. A search is refused beyond ``search_memory_bytes`` by its estimate
    (``toptraj.planners.generators.search.memory``)."""
    robot = equipped_robot(request)
    with payload_named(robot):
        return plan(_problem(request, robot, deadline or NO_DEADLINE, max_body_bytes, accept, search_memory_bytes))


def check_request(request: TrajectoryRequest, max_body_bytes: int | None = None, search_memory_bytes: int = DEFAULT_SEARCH_MEMORY) -> None:
    """Refuse ``request`` as ``plan_request`` would before any work, without planning: its
    problem built and validated (fields, limits, a free path's start and goal) and its memory
    estimate (``toptraj.planners.plan.check``). A job is checked so before it is queued.

    Raises:
        InvalidRequest, InfeasiblePath, InvalidLimits, InvalidEquipment, OverMemory,
        UnknownRobot: as ``plan_request`` would.
    """
    robot = equipped_robot(request)
    with payload_named(robot):
        check(_problem(request, robot, NO_DEADLINE, max_body_bytes, None, search_memory_bytes))


def _problem(request: TrajectoryRequest, robot: robots.Robot, deadline: Deadline, max_body_bytes: int | None, accept: str | None, search_memory_bytes: int):
    """The validated problem of ``request`` for ``robot``, its samples within ``max_body_bytes``."""
    format_ = chosen_format(request.output.format, accept)
    max_samples = MAX_SAMPLES if max_body_bytes is None else min(MAX_SAMPLES, samples_within(max_body_bytes, robot.dof, format_))
    exact_period = exact_period_for(format_, request.output.exact_period)
    return problem_of(request, robot, deadline, max_samples, exact_period, search_memory_bytes)


def render(result: PlannedTrajectory, request: TrajectoryRequest, accept: str | None = None) -> tuple[bytes, str]:
    """The answer's bytes and media type in the format asked (``toptraj.service.formats``)."""
    format_ = chosen_format(request.output.format, accept)
    body = trajectory_body(result) | equipment_body(request)
    if format_ == "csv":
        return csv_bytes(body), CSV_MEDIA_TYPE
    if format_ == "joint_trajectory":
        del body["samples"]
        body["joint_trajectory"] = joint_trajectory(result)
    return encode_json(body), "application/json"


#: The rules of the notes on how samples render a motion (``planners.runner.sampling_notes``).
SAMPLING_RULES = ("too_few_samples", "slowed_to_whole_periods")


def method_request(request: CompareRequest, method: str, dt: float = 1.0) -> TrajectoryRequest:
    """The trajectory request of one method of a comparison, sampled every ``dt`` seconds."""
    return TrajectoryRequest(
        robot=request.robot,
        payload=request.payload,
        mounting=request.mounting,
        path=request.path,
        timing=request.timing.model_copy(update={"method": method}),
        output=OutputRequest(dt=dt),
    )


def requested_limits(request: TrajectoryRequest | CompareRequest, robot: robots.Robot) -> robots.JointLimits:
    """The robot's limits with the request's overrides and scale factors applied."""
    limits = request.timing.limits
    kinds = ("velocity", "acceleration", "jerk", "torque")
    return robot.limits.with_request({kind: getattr(limits, kind) for kind in kinds}, {kind: getattr(limits, f"{kind}_scale") for kind in kinds})


def compare_results(request: CompareRequest, deadline: Deadline, dt: float = 1.0) -> list[tuple[dict, PlannedTrajectory | None]]:
    """Run every method of ``request`` on the same path and limits, sampled every ``dt``
    seconds: each method's entry of the comparison with its trajectory, or, when the method
    itself fails, an entry naming its error and ``None``."""
    results: list[tuple[dict, PlannedTrajectory | None]] = []
    count = len(request.methods)
    for index, method in enumerate(request.methods):
        part = deadline.within(index / count, (index + 1) / count, f"{method} ({index + 1} of {count})")
        try:
            result = plan_request(method_request(request, method, dt), part)
        except UnknownRobot:
            raise
        except (InvalidRequest, InfeasiblePath, TimingFailed, InvalidLimits, OverMemory, ShareSpent) as error:
            results.append(({"method": method, "error": {"status": status_of(error), "title": title_of(error), "detail": detail(error)}}, None))
            continue
        body = trajectory_body(result)
        entry = {key: body[key] for key in ("method", "duration", "peak_utilization", "binding", "solve_ms", "accuracy")}
        # a comparison returns no samples: what its coarse sampling renders is no news to its reader
        entry["warnings"] = [note_text(note) for note in result.warnings if getattr(note, "rule", None) not in SAMPLING_RULES]
        results.append((entry, result))
    return results


def compare_request(request: CompareRequest, deadline: Deadline) -> dict:
    """Run every method of ``request`` on the same path and limits; a method's own failure is
    reported in its entry instead of failing the comparison."""
    return {"results": [entry for entry, _ in compare_results(request, deadline)]}


def _finite_or_none(values) -> np.ndarray | list[float | None]:
    """Non-finite values (an unbounded MVC) as JSON nulls: the array as it is when all are
    finite (orjson writes it directly), else a list with ``None`` in their place."""
    array = np.asarray(values, dtype=float)
    if np.isfinite(array).all():
        return array
    return [_finite_scalar(v) for v in array]


def _finite_scalar(value: float) -> float | None:
    """A non-finite value (a singular Jacobian's condition number) as a JSON null."""
    return float(value) if math.isfinite(value) else None


def _utilization_values(values: np.ndarray) -> list[float | None] | float | None:
    """A peak utilization for JSON: a joint (or tool limit) without a finite limit as null."""
    array = np.asarray(values, dtype=float)
    if array.ndim == 0:
        return _finite_scalar(float(array))
    return [_finite_scalar(v) for v in array.tolist()]


def trajectory_body(result: PlannedTrajectory) -> dict:
    """The JSON body of a planned trajectory (DESIGN.md contract); the samples stay numpy arrays
    until ``encode_json``."""
    samples = result.samples
    conditioning = result.conditioning
    assert conditioning is not None  # plan() measures it on every answer
    return {
        "robot": result.robot,
        "method": result.method,
        "joint_names": list(result.joint_names),
        "duration": result.duration,
        "sampled_duration": float(samples.t[-1]),
        "samples": {"t": samples.t, "q": samples.q, "qd": samples.qd, "qdd": samples.qdd, "tau": samples.tau},
        "phase_plane": {
            "s": result.phase_plane.s,
            "sd": result.phase_plane.sd,
            "sd_max": _finite_or_none(result.phase_plane.sd_max),
            "switch_points": [{"s": s, "kind": kind} for s, kind in result.phase_plane.switch_points],
        },
        "peak_utilization": {kind: _utilization_values(values) for kind, values in result.peak_utilization.items()},
        "binding": None if result.binding is None else {
            "kind": result.binding.kind, "joint": result.binding.joint, "s": result.binding.s
        },
        "conditioning": {
            "kappa_min": _finite_scalar(conditioning.kappa_min),
            "kappa_max": _finite_scalar(conditioning.kappa_max),
            "characteristic_length": conditioning.characteristic_length,
        },
        "cost": result.cost,
        "solver": solver_body(result.solver),
        "switching_times": switching_body(result.switching_times),
        "solve_ms": result.solve_ms,
        "warnings": [note_text(note) for note in result.warnings],
        "min_clearance": None if result.clearance is None else {
            "distance": result.clearance.distance,
            "link": result.clearance.link,
            "obstacle": result.clearance.obstacle,
            "s": result.clearance.s,
        },
        "search": search_body(result.search),
        "accuracy": accuracy_body(result),
        "zones": None if result.zones is None else [
            {"index": zone.index, "ranges": [list(item) for item in zone.ranges], "peak": zone.peak, "binding": zone.binding}
            for zone in result.zones
        ],
    }


def accuracy_body(result: PlannedTrajectory) -> dict:
    """``{"relative_gap", "basis"}``: the answer's estimated relative distance from the
    converged optimum of its method's problem (``toptraj.planners.runner.accuracy``), null when not estimated."""
    accuracy = result.accuracy
    if accuracy is None:
        return {"relative_gap": None, "basis": f"not estimated for timing.method {result.method}"}
    return {"relative_gap": accuracy.relative_gap, "basis": note_text(accuracy.basis)}


def _plain(value):
    """What orjson leaves to its caller: numpy arrays that are not C-contiguous."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def encode_json(body: dict) -> bytes:
    """``body`` as JSON bytes: numpy arrays are written directly by orjson (no ``tolist()``).

    Raises:
        NonFiniteAnswer: a number is NaN or infinite (JSON cannot carry it; orjson would write
            ``null``).
    """
    error = non_finite_answer(body)
    if error is not None:
        raise error
    return orjson.dumps(body, default=_plain, option=orjson.OPT_SERIALIZE_NUMPY)
