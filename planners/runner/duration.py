"""A duration given too short for its time law under the limits: the shortest that holds them.

A time law stretched over a duration ``T`` scales its joint velocities by ``1/T`` and its
accelerations by ``1/T^2`` (Biagiotti & Melchiorri, *Trajectory Planning for Automatic
Machines and Robots*, 2008, §3.1); a duration below the law's shortest under the limits breaks
one, whatever the grid or a lower scale. The shortest is found by planning the same problem
without a duration (``toptraj.planners.timing.laws``: the law slowed until every limit holds), and
stated only when that planning succeeds within its share of the deadline.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, LimitExceeded, TimingFailed
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.problem.problem import Problem
from toptraj.planners.results import PlannedTrajectory

#: Share of the seconds remaining that the search for the shortest duration may take.
SHORTEST_SHARE = 0.5
#: Significant digits of the shortest duration stated (rounded up, so that it holds the limits).
STATED_DIGITS = 3


def rounded_up(seconds: float, digits: int = STATED_DIGITS) -> float:
    """``seconds`` (> 0) rounded up to ``digits`` significant digits."""
    step = 10.0 ** (math.floor(math.log10(seconds)) - digits + 1)
    return round(math.ceil(seconds / step - 1e-9) * step, 12)


def rounded_down(value: float, digits: int = STATED_DIGITS) -> float:
    """``value`` (> 0) rounded down to ``digits`` significant digits (advice that, followed as
    printed, stays within the bound it comes from)."""
    step = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return round(math.floor(value / step + 1e-9) * step, 12)


def too_short(problem: Problem, error: LimitExceeded, run: Callable[[Problem], PlannedTrajectory]) -> LimitExceeded:
    """``error`` (a limit exceeded by the timing of ``problem``, whose duration was given) with
    the shortest duration that holds the limits when the duration is what breaks them: the same
    problem run without a duration, within ``SHORTEST_SHARE`` of the deadline, gives a duration
    above the one given, and that duration, rounded up to ``STATED_DIGITS``, holds the limits
    when given (``_followable``). Facts added: ``rule`` ``"duration_too_short"``, ``field``
    ``"duration"``, ``value`` (s, given), ``shortest`` (s, found without a duration),
    ``stated`` (s, a duration that holds the limits) and ``exact`` (whether ``stated`` is
    ``shortest`` rounded up). Otherwise ``error`` as it is."""
    given = problem.duration
    assert given is not None
    part = problem.deadline.share(SHORTEST_SHARE)
    try:
        shortest = run(dataclasses.replace(problem, duration=None, deadline=part)).duration
        stated = _followable(problem, part, rounded_up(shortest), run) if shortest > given else None
    except BudgetExceeded:
        problem.deadline.check()  # a caller's cancellation or the whole budget spent stops here
        return error
    except (InfeasiblePath, TimingFailed):
        return error
    if stated is None:
        return error
    facts = {key: value for key, value in vars(error).items() if key != "detail"}
    exact = stated == rounded_up(shortest)
    facts.update(rule="duration_too_short", field="duration", value=given, shortest=shortest, stated=stated, exact=exact)
    return LimitExceeded(
        f"the duration {given:g} s is too short for the {getattr(error, 'method', 'timing')} law under these limits: "
        f"{'the shortest is' if exact else 'a duration of'} {stated:g} s holds them ({error.detail})",
        **facts,
    )


#: Longer durations tried when the shortest found, given as the duration, still breaks a limit
#: (a motion whose pieces share a given duration otherwise than its shortest does: via points).
FOLLOWABLE_TRIES = 6


def _followable(problem: Problem, deadline: Deadline, candidate: float, run: Callable[[Problem], PlannedTrajectory]) -> float | None:
    """The first of ``candidate`` and up to ``FOLLOWABLE_TRIES`` longer durations with which
    ``problem`` holds its limits, or ``None``. Each next one is longer by the square root of
    the excess found (accelerations scale with 1/T^2), by 1 % at least."""
    for _ in range(FOLLOWABLE_TRIES + 1):
        try:
            run(dataclasses.replace(problem, duration=candidate, deadline=deadline))
        except LimitExceeded as error:
            ratio = float(getattr(error, "ratio", 1.0))
            candidate = rounded_up(candidate * max(math.sqrt(ratio), 1.01))
            continue
        return candidate
    return None
