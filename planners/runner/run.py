"""The runner: a ``Problem`` solved by its method, whichever family it belongs to, through the
same deadline, limit gate and answer.

A timing method times the given path (built here, checked for clearance, each stretch through
the gate: ``toptraj.planners.runner.given_path``); a motion generator finds and times the
motion itself, with the given-path pipeline lent to it (``Execution``). Then both go the same
way (``toptraj.planners.runner.answer``): sampled, the samples checked against the limits, the
accuracy stated, the phase plane and the peak utilization read off.
"""

from __future__ import annotations

import dataclasses
import time

from toptraj.planners.collision import check_clearance
from toptraj.planners.collision.clearance import Clearance
from toptraj.planners.collision.self_collision import check_self_collision
from toptraj.planners.errors import InfeasiblePath, LimitExceeded, numerical_breakdown_is_failure
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import Execution, MotionGenerator, Timed
from toptraj.planners.problem.problem import Problem
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.problem.zones import zone_limits
from toptraj.planners.results import PlannedTrajectory
from toptraj.planners.runner.admission import admit
from toptraj.planners.runner.answer import answer
from toptraj.planners.runner.duration import too_short
from toptraj.planners.runner.given_path import timed_path
from toptraj.planners.runner.holding import with_torque_remedy, zone_remedy
from toptraj.planners.runner.other_method import with_other_method
from toptraj.planners.timing.base import TimingMethod


def run(problem: Problem) -> PlannedTrajectory:
    """The timed trajectory of ``problem``, sampled, checked and with its stated accuracy.

    Raises:
        TooLarge: before any work, a problem whose memory estimate exceeds the cap (the largest
            grid that fits is named: ``toptraj.planners.runner.admission``); after the timing, a
            ``dt`` that gives more samples than the problem allows (the smallest that fits).
        OverMemory: before any work, a search whose graph exceeds its allowance.
        InvalidRequest: what only the built path shows.
        InfeasiblePath: no timing can follow the path within the limits (says where, which
            joint and which limit).
        TimingFailed: the method failed.
        BudgetExceeded: the problem's deadline passed.
    """
    try:
        return _run(problem)
    except InfeasiblePath as error:
        stated = error
        if isinstance(error, LimitExceeded) and problem.duration is not None:
            stated = too_short(problem, error, _run)
        elif not getattr(error, "joints", None):  # not the torque of holding still: a timing's own failure
            stated = with_other_method(problem, error, _run)
        if getattr(stated, "joints", None):
            stated = with_torque_remedy(problem, stated)
        if stated is error:
            raise
        raise stated from error


def _run(problem: Problem) -> PlannedTrajectory:
    """``run`` without the search for a shorter duration's remedy."""
    started = time.perf_counter()
    admit(problem)
    method, part = problem.method, problem.deadline.within(0.0, 0.9)
    checked_first = None
    with numerical_breakdown_is_failure(method.name):
        if isinstance(method, MotionGenerator):
            timed = method.generate(problem, Execution(part, timed_path, isolate=isolates(method, problem.deadline)))
            if problem.self_collision and method.name != "search":  # the search checks its own paths
                check_self_collision(timed.path, problem.robot, deadline=problem.deadline)
        else:
            timed, checked_first, problem = _given_path(problem, part)
    return answer(problem, timed, checked_first, started)


def isolates(method: TimingMethod | MotionGenerator, deadline: Deadline) -> bool:
    """Whether ``method``'s uninterruptible step runs in a worker process (``Execution.isolate``):
    for a method that cannot check its deadline (``interruptible`` false), when there is a
    deadline to stop it at (a budget, or a caller that may cancel) and this is no worker process
    already (a job's, killed whole). Interruptible methods, the typical request's among them,
    never start one (nor import the worker processes' module)."""
    if method.interruptible or deadline is NO_DEADLINE:
        return False
    from toptraj.planners.execution.isolated import in_worker

    return not in_worker()


def _given_path(problem: Problem, part: Deadline) -> tuple[Timed, Clearance | None, Problem]:
    """The given path built, kept clear of the obstacles, and timed by the problem's timing
    method; with the clearance found, when there are obstacles, and the problem with its zones
    located on the path."""
    part.progress(0.0, "path")
    assert not isinstance(problem.motion, FreeMotion)  # build_problem gives free motions to generators
    path = make_path(problem.robot, problem.motion, problem.deadline)
    problem = _with_zones(problem, path)
    checked = None
    if problem.obstacles:
        part.progress(0.05, "clearance")
        checked = check_clearance(path, problem.robot, list(problem.obstacles), problem.clearance, problem.deadline)
    if problem.self_collision:
        part.progress(0.07, "self-collision")
        check_self_collision(path, problem.robot, deadline=problem.deadline)
    assert isinstance(problem.method, TimingMethod)  # run gives the generators' problems to them
    try:
        timed = timed_path(
            problem.robot, path, problem.method, problem.grid, problem.boundary, problem.duration, problem.kinds, problem.limits,
            part.within(0.1, 1.0), problem.threshold,
        )
    except InfeasiblePath as error:
        if problem.limits.zones and getattr(error, "joints", None):  # the zones' own remedy, on the located zones
            error.__dict__["zone_scales"] = zone_remedy(problem, path)
        raise
    return timed, checked, problem


def _with_zones(problem: Problem, path) -> Problem:
    """The problem with its zones located on ``path`` (a region where the tool frame's origin,
    the end effector's without a tool limit, lies in it), tightened by the margin, and a note for
    each region the path never enters."""
    zones, limits, robot = problem.requested.zones, problem.limits, problem.robot
    if not zones:
        return problem
    frame_id = robot.frame_id(robot.end_effector) if limits.tool is None else limits.tool.frame_id
    located, missed = zone_limits(robot, path, zones, frame_id, problem.deadline)
    zoned = dataclasses.replace(limits, zones=tuple(zone.tightened(problem.margin) for zone in located))
    return dataclasses.replace(problem, limits=zoned, notes=(*problem.notes, *missed))
