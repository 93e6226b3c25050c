"""A path toppra's grid cannot time, timed by the phase-plane integrator instead, as advice.

TOPP-RA (Pham & Pham 2018) holds the constraints at its grid points only, with the path
acceleration constant over each interval; where the path turns sharply within an interval, or
the speed must fall nearly to rest at a point (two waypoints nearly repeated, a tight blend), its
controllable sets can come out empty, or its refined grid keep exceeding a limit between
points, although a motion exists. The phase-plane integrator (Pfeiffer & Johanni 1987; Shin &
McKay 1985) follows the maximum velocity curve exactly there. When it answers the same problem,
its duration is named in the refusal, a remedy known to work, not one to try.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, LimitExceeded
from toptraj.planners.problem.problem import Problem
from toptraj.planners.results import PlannedTrajectory
from toptraj.planners.timing import METHODS
from toptraj.robots.errors import ToptrajError

#: Methods whose refusals are checked against the phase-plane integrator.
CHECKED = ("toppra",)
#: Share of the seconds remaining that the phase-plane timing may take.
SHARE = 0.3


def with_other_method(problem: Problem, error: InfeasiblePath, run: Callable[[Problem], PlannedTrajectory]) -> InfeasiblePath:
    """``error`` (``problem``'s method refusing the path, its duration free) with facts
    ``alternative`` ("phase_plane") and ``alternative_duration`` (s) when the phase-plane
    integrator times the same problem within ``SHARE`` of the deadline; otherwise ``error``."""
    alternative = METHODS["phase_plane"]
    if (problem.method.name not in CHECKED or problem.duration is not None or not set(problem.kinds) <= set(alternative.kinds)
            or type(error) not in (InfeasiblePath, LimitExceeded) or getattr(error, "rule", None) is not None):
        return error  # the path's own refusals (collisions, ranges) and worded rules are told as they are
    part = problem.deadline.share(SHARE)
    try:
        answer = run(dataclasses.replace(problem, method=alternative, deadline=part))
    except BudgetExceeded:
        problem.deadline.check()  # a caller's cancellation or the whole budget spent stops here
        return error
    except ToptrajError:  # no answer within the limits, or none the answer's caps allow: no advice
        return error
    facts = {key: value for key, value in vars(error).items() if key != "detail"}
    facts.update(alternative="phase_plane", alternative_duration=answer.duration)
    return type(error)(f"{error.detail}; the phase_plane method times this path in {answer.duration:.4g} s", **facts)
