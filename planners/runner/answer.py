"""From a timed motion to the answer, the same for every method: the samples (checked against
the limits once more), the stated accuracy, the peak utilization, the conditioning, the switching
times, the phase plane, and the notes that tell what the numbers alone do not."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, cast

import numpy as np

from toptraj.planners.checks.gate import TimedStretch, samples_exceed
from toptraj.planners.collision import check_clearance
from toptraj.planners.collision.clearance import Clearance
from toptraj.planners.constraints.admissible import admissible_set
from toptraj.planners.constraints.zones import BINDING_SHARE
from toptraj.planners.errors import TimingFailed
from toptraj.planners.kinematics.conditioning import NEAR_SINGULAR_KAPPA, conditioning_along
from toptraj.planners.paths.blended import MIN_BLEND, BlendedPath
from toptraj.planners.paths.grid import spread_indices
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import MotionGenerator, Timed
from toptraj.planners.problem.problem import Problem
from toptraj.planners.results import Accuracy, Conditioning, PhasePlane, PlannedTrajectory, ZoneReport, require_finite
from toptraj.planners.runner.accuracy import answer_accuracy
from toptraj.planners.runner.admission import admit_samples
from toptraj.planners.runner.sampling_notes import sampling_notes
from toptraj.planners.timing.base import TimingMethod
from toptraj.planners.timing.laws.law_timing import LawTiming
from toptraj.planners.timing.laws.method import ClassicalMethod
from toptraj.planners.trajectory import Samples, sample_trajectory
from toptraj.robots import JointLimits, Robot
from toptraj.robots.notes import Note

if TYPE_CHECKING:  # the generators' reports, imported where a generator ran
    from toptraj.planners.generators.collocation.report import CollocationReport
    from toptraj.planners.generators.search.report import SearchReport

#: Seconds the sampling takes per sample and joint, with the checks, the conditioning and the
#: encoding of the answer that follow it (measured about 0.3 us on ur5 at 236 to 23,409
#: samples; twice that, for slower machines): what ``Deadline.expect`` is told before it.
SAMPLE_SECONDS = 5e-7
#: Largest number of phase-plane points returned (the grid is thinned evenly beyond it).
MAX_PHASE_PLANE_POINTS = 2_000
#: Largest number of samples whose Jacobian is conditioned (evenly spaced among them).
CONDITIONING_POINTS = 100
#: Share of its limit beyond which a sampled torque counts as saturated when switching times
#: are read off the samples.
SATURATION_READ = 0.98
#: Peak utilization of a limit kind not among the constraints above which the answer says so.
UNASKED_EXCESS = 1.005


def answer(problem: Problem, timed: Timed, checked_first: Clearance | None, started: float) -> PlannedTrajectory:
    """The answer to ``problem`` from its timed motion (``checked_first``: the clearance of a
    given path, found before its timing; ``started``: ``time.perf_counter()`` at the start)."""
    robot, deadline, result = problem.robot, problem.deadline, timed.timing
    notes = [*problem.notes, *timed.notes, *_blend_notes(timed.path, getattr(problem.motion, 'origin', None))]
    deadline.check()
    found_clearance = None
    if problem.obstacles:
        # a given path was checked before its timing; a path shaped with its timing (via points) now
        found_clearance = checked_first or check_clearance(timed.path, robot, list(problem.obstacles), problem.clearance, deadline)
        notes.extend(_far_obstacles(found_clearance, robot))
    deadline.progress(0.9, "sampling")
    samples = _samples(problem, timed)
    accuracy, warning = _accuracy(problem, timed)
    if warning is not None:
        notes.append(warning)
    utilization = _utilization(timed.stretches, problem.margin, problem.limits)
    notes.extend(_jumping_jerk(problem.method, utilization))
    notes.extend(_unheld_defaults(problem, utilization))
    notes.extend(_unasked_limits(utilization, (*problem.kinds, *problem.unheld), problem.method, robot.joint_names))
    kappa_min, kappa_max, length, worst = conditioning_along(robot, samples.q, spread_indices(len(samples.q), CONDITIONING_POINTS))
    notes.extend(_singularity_notes(kappa_min, kappa_max, samples.t[worst], isinstance(problem.motion, FreeMotion)))
    notes.extend(sampling_notes(result.duration, problem.sampling.dt, problem.sampling.exact_period, len(samples.t)))
    switching = timed.switching_times
    if switching is None and timed.method == "collocation" and getattr(problem.method, "torque_weight", None) == 0.0:
        from toptraj.planners.generators.collocation.bang_bang import collocation_switches, switching_times

        read = collocation_switches(samples.t, samples.tau, problem.limits.torque, level=SATURATION_READ)
        switching = switching_times(read, robot.joint_names)
    s, sd, mvc = _phase_plane(timed.stretches)
    require_finite(timed.method, path_speed=sd, cost=timed.cost)
    solver = cast("CollocationReport | None", timed.solver)
    search = cast("SearchReport | None", timed.search)
    return PlannedTrajectory(
        robot=robot.name, method=timed.method, joint_names=robot.joint_names, duration=result.duration, samples=samples,
        phase_plane=PhasePlane(s, sd, mvc, result.switch_points), peak_utilization=utilization,
        solve_ms=(time.perf_counter() - started) * 1e3, warnings=tuple(notes), binding=result.binding,
        conditioning=Conditioning(kappa_min, kappa_max, length), cost=timed.cost, solver=solver,
        switching_times=switching, clearance=found_clearance, search=search, accuracy=accuracy,
        zones=_zone_reports(problem.limits.zones, timed.stretches, problem.margin) if problem.requested.zones else None,
    )


def _zone_reports(zones, stretches_: tuple[TimedStretch, ...], margin: float) -> tuple[ZoneReport, ...]:
    """Where each zone lies and its peak inside over every stretch (``ZoneReport``), against its
    limits as requested (before any margin); it binds where it reaches the limits it was
    planned under (tightened by the margin)."""
    reports = []
    for zone in zones:
        peak = max((item.check.zones.get(zone.index, 0.0) for item in stretches_), default=0.0)
        reports.append(ZoneReport(zone.index, zone.ranges, (1.0 - margin) * peak, peak >= BINDING_SHARE))
    return tuple(reports)


def _blend_notes(path, origin: tuple[int, ...] | None) -> list[Note]:
    """Corners a blend could not round (its radius below ``MIN_BLEND`` of the path): the motion
    stops there. Those the path's deviation limits, and those two short segments limit (a larger
    deviation does not round them), in a note each. ``origin``: the index as given of each
    waypoint of the path (``None``: as given)."""
    if not (isinstance(path, BlendedPath) and path.tight_corners):
        return []
    named = (lambda corner: corner) if origin is None else origin.__getitem__
    by_deviation = tuple(named(corner) for corner in path.tight_by_deviation)
    by_segments = tuple(named(corner) for corner in path.tight_corners if corner not in path.tight_by_deviation)
    notes = []
    if by_deviation:
        notes.append(Note(
            f"the largest deviation {path.max_deviation:g} is too small to blend the corners at waypoints "
            f"{', '.join(map(str, by_deviation))} (a blend of radius below {MIN_BLEND:g} of the path): the motion "
            "stops there",
            "corners_not_blended", field="max_deviation", value=path.max_deviation, corners=by_deviation,
            min_blend=MIN_BLEND,
        ))
    if by_segments:
        notes.append(Note(
            f"the corners at waypoints {', '.join(map(str, by_segments))} turn too sharply for the segments beside "
            f"them (a blend within half of each has a radius below {MIN_BLEND:g} of the path): the motion stops there",
            "corners_between_short_segments", field="waypoints", corners=by_segments, min_blend=MIN_BLEND,
        ))
    return notes


def _samples(problem: Problem, timed: Timed) -> Samples:
    """The motion sampled every ``dt``, every sample checked against the limits (the gate's
    threshold; a continuous acceleration's jerk too)."""
    robot, result, sampling, method = problem.robot, timed.timing, problem.sampling, problem.method
    require_finite(timed.method, duration=result.duration)
    admit_samples(problem, result.duration)
    problem.deadline.expect((result.duration / sampling.dt + 2) * robot.dof * SAMPLE_SECONDS)
    samples = sample_trajectory(timed.path, result, robot, sampling.dt, sampling.exact_period)
    require_finite(timed.method, samples=[samples.q, samples.qd, samples.qdd, samples.tau])
    beyond = samples_exceed(samples, problem.limits, problem.threshold, problem.kinds, robot, jerk=method.continuous_acceleration)
    if beyond is None:
        return samples
    kind, sample, joint = beyond
    what = f"{kind} limit of joint {robot.joint_names[joint]!r}" if joint >= 0 else f"{kind.replace('_', ' ')} limit"
    if kind == "jerk":
        raise TimingFailed(
            f"the {timed.method} timing's accelerations jump between the samples at t = "
            f"{samples.t[sample]:.6g} s and {samples.t[sample + 1]:.6g} s: the jerk from the samples "
            f"exceeds the {what}"
        )
    raise TimingFailed(
        f"the {timed.method} timing's sample at t = {samples.t[sample]:.6g} s exceeds the {what} "
        "although its dense check holds; use more grid points"
    )


def _accuracy(problem: Problem, timed: Timed) -> tuple[Accuracy, str | None]:
    """The answer's stated accuracy (``toptraj.planners.runner.accuracy``) and a warning when it
    is short of the target: a free path's own gap, else the timing's."""
    if timed.motion_gap is not None:  # a free path: the gap of the motion found, warned of where it is found
        return Accuracy(*timed.motion_gap), None
    method = problem.method
    timed_by = method.timed_by if isinstance(method, MotionGenerator) else method
    # Time laws at their shortest, also through via points or joint by joint: every stretch
    # timed by a law, its peak utilization read off its dense check.
    by_law = isinstance(timed_by, ClassicalMethod)
    laws = [
        (item.timing.duration, {kind: peak for kind, peak in item.check.utilization.items() if kind in problem.kinds or kind.startswith("tool")})
        for item in timed.stretches
        if by_law or isinstance(item.timing, LawTiming)
    ]
    intervals = sum(len(item.constraints.s) - 1 for item in timed.stretches)
    return answer_accuracy(
        timed.timing, timed_by, timed.method, intervals, problem.robot.dof, grid_given=problem.grid is not None,
        duration_given=problem.duration is not None, law_utilization=laws if len(laws) == len(timed.stretches) else None,
    )


def _singularity_notes(kappa_min: float, kappa_max: float, at: float, free: bool = False) -> list[str]:
    """A note when the arm passes through or near a singularity (at ``at``, s), or stays in one
    all along (``kappa_min`` infinite: no single instant to name), each with what to do; a free
    path (``free``) has no waypoints to move, only its start and goal."""
    unaffected = "the timing is unaffected, but the tool's motion is poorly controlled near that pose"
    remedy = (
        "to avoid it at an end of the motion, move its start or goal off that pose (between them, the path is the planner's)"
        if free else f"to avoid it, move the path's waypoints near t = {at:.4g} s off that pose (a Cartesian path: give it in joint space there)"
    )
    if not np.isfinite(kappa_min):
        return [
            "the arm is at a singularity all along the motion: its end effector's Jacobian lacks full rank at every "
            "sample conditioned (the condition number is infinite throughout, as for an end effector on a joint's "
            "axis); the timing is unaffected, and a motion given in joint space needs no change"
        ]
    if not np.isfinite(kappa_max):
        return [
            f"the arm passes through a singularity at t = {at:.4g} s: its Jacobian loses rank there (the condition "
            f"number is infinite); {unaffected}; {remedy}"
        ]
    if kappa_max > NEAR_SINGULAR_KAPPA:
        return [
            f"the arm passes near a singularity: the Jacobian's condition number reaches {kappa_max:.4g} at t = {at:.4g} s; "
            f"{unaffected}; {remedy}"
        ]
    return []


def _phase_plane(stretches_: tuple[TimedStretch, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, sd and the maximum velocity curve (1/s) over the grids the stretches were timed on,
    in the path's own s."""
    pieces = []
    for item in stretches_:
        constraints = item.constraints
        sd = item.timing.speed_at(constraints.s)
        mvc = admissible_set(constraints.linearized(sd**2), constraints.sd_max**2).sd_max
        start, width = getattr(item.stretch, "start", 0.0), getattr(item.stretch, "width", 1.0)
        pieces.append((start + width * constraints.s, width * sd, width * mvc))
    s, sd, mvc = (np.concatenate([piece[i] for piece in pieces]) for i in range(3))
    keep = spread_indices(len(s), MAX_PHASE_PLANE_POINTS)
    return s[keep], sd[keep], mvc[keep]


def _utilization(stretches_: tuple[TimedStretch, ...], margin: float, limits: JointLimits) -> dict[str, np.ndarray]:
    """Peak |value| / limit per kind and joint over every stretch, against the limits as
    requested (before any margin); ``nan`` for a joint and kind without a finite limit (in
    ``limits``, (n_dof,) each) that no zone limited either (its peak stays 0)."""
    # a kind a zone limits on some stretches only (a tool speed) counts where it is checked
    kinds = dict.fromkeys(kind for item in stretches_ for kind in item.check.utilization)
    peaks = {
        kind: np.max([item.check.utilization[kind] for item in stretches_ if kind in item.check.utilization], axis=0)
        for kind in kinds
    }
    for kind, peak in peaks.items():
        limit = getattr(limits, kind, None)
        if limit is not None and np.shape(limit) == np.shape(peak):
            peaks[kind] = np.where(~np.isfinite(limit) & (peak == 0.0), np.nan, peak)
    return {kind: (1.0 - margin) * peak for kind, peak in peaks.items()}


def _jumping_jerk(method: TimingMethod | MotionGenerator, utilization: dict[str, np.ndarray]) -> list[str]:
    """A motion whose acceleration jumps (``continuous_acceleration`` false) has an infinite
    jerk at each jump, whatever its duration; the finite peak between the jumps would read as
    the motion's, so ``utilization`` loses its jerk, as a phase-plane answer has none. A time
    law's answer (cubic, trapezoidal), whose law was chosen, says why in a note."""
    if "jerk" not in utilization or method.continuous_acceleration:
        return []
    del utilization["jerk"]
    profile = getattr(getattr(method, "law", method), "profile", None)
    if profile is None:  # a collocation's bang-bang motion: no jerk, as phase_plane's
        return []
    where = ", ".join(f"{tau:.4g}" for tau in profile.acceleration_steps())
    return [
        f"the {profile.description}'s acceleration jumps at tau = {where} (as a fraction of each stretch's duration), "
        "so its jerk is infinite there: peak_utilization leaves the jerk out (quintic, cycloidal, trapezoidal with a "
        "cycloidal blend, ruckig and jerk_limited keep the jerk finite)"
    ]


def _unheld_defaults(problem: Problem, utilization: dict[str, np.ndarray]) -> list[Note]:
    """A note for each default limit kind the method cannot hold (``Problem.unheld``): the
    answer does not hold it, and its peak |value| / limit over the joints (``peak``, on
    ``joint``) is stated where the robot has such limits (``None`` where none is finite)."""
    notes = []
    for kind in problem.unheld:
        peak = np.atleast_1d(np.asarray(utilization.get(kind, ()), dtype=float))
        finite = np.isfinite(peak)
        worst = int(np.argmax(np.where(finite, peak, -np.inf))) if finite.any() else None
        joint = None if worst is None else problem.robot.joint_names[worst]
        value = None if worst is None else float(peak[worst])
        said = "" if worst is None else f"; its peak is {value:.4g} times the limit of joint {joint!r}"
        notes.append(Note(
            f"the {kind} limits are not held: {problem.method.name} cannot hold them, and the limit kinds were "
            f"not given (the default kinds that {problem.method.name} holds were used){said}",
            "default_kind_not_held", kind=kind, method=problem.method.name, kinds=problem.kinds, peak=value, joint=joint,
        ))
    return notes


def _unasked_limits(
    utilization: dict[str, np.ndarray], kinds: tuple[str, ...], method: TimingMethod | MotionGenerator, joint_names: tuple[str, ...]
) -> list[str]:
    """A note for each joint limit the answer exceeds by more than ``UNASKED_EXCESS`` where
    that kind of limit was not among the constraints (``kinds``): the answer is right, but a
    reader of its peak utilization must not take it for a broken promise."""
    notes = []
    for kind, peak in utilization.items():
        peak = np.atleast_1d(np.asarray(peak, dtype=float))
        if kind in kinds or kind.startswith("tool") or not np.any(peak > UNASKED_EXCESS):
            continue
        joint = int(np.nanargmax(peak))
        name = joint_names[joint] if peak.size == len(joint_names) else f"joint {joint}"
        remedy = f"add {kind!r} to the constraints to hold it" if kind in method.kinds else f"{method.name} cannot hold {kind} limits"
        notes.append(f"the {kind} of joint {name!r} reaches {peak[joint]:.4g} times its limit, which was not asked for: {remedy}")
    return notes


#: Obstacles farther from the arm than this many times its reach, all of them, are noted: a
#: position given in millimetres, or in another frame, would otherwise check nothing unnoticed.
FAR_REACHES = 10.0


def _far_obstacles(found: Clearance, robot: Robot) -> list[Note]:
    """A note when even the nearest obstacle stays ``FAR_REACHES`` times the arm's reach away."""
    reach = robot.neutral_reach
    if not (reach > 0.0 and found.distance > FAR_REACHES * reach):
        return []
    return [Note(
        f"the obstacles stay at least {found.distance:.4g} m from the arm, {found.distance / reach:.0f} times its reach",
        "obstacles_far", field="obstacles", distance=found.distance, reach=reach,
    )]
