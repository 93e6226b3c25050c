"""``plan``: from a planning problem to a timed trajectory with torques.

Data flow (DESIGN.md): the problem built and validated once (``build_problem``: the method of
either family with its options, the limits, the motion) -> the runner (``run``): a timing method
times the given path (GeometricPath q(s) -> PathConstraints on a grid -> TimeScaling s(t),
through the limit gate), a motion generator finds the motion and times it -> samples, phase
plane, peak utilization and the stated accuracy.
"""

from __future__ import annotations

from toptraj.planners.problem.problem import Problem
from toptraj.planners.results import PlannedTrajectory
from toptraj.planners.runner.admission import admit
from toptraj.planners.runner.run import run


def plan(problem: Problem) -> PlannedTrajectory:
    """Plan the timed trajectory of ``problem`` (``toptraj.planners.problem.build.build_problem``),
    sampled every ``problem.sampling.dt`` seconds into at most ``max_samples`` samples. With
    ``exact_period`` the samples lie on whole periods ``dt``, the final state included: the
    motion is slowed uniformly to end on one (``toptraj.planners.trajectory.sample_trajectory``);
    ``duration`` stays the planned (optimal) one and ``sampled_duration`` is the samples' last
    instant. With obstacles (world frame), every link keeps the problem's clearance (m) from them
    along the path (``toptraj.planners.collision``), and the answer carries the smallest distance
    found. With ``self_collision`` no two links of the arm touch along the path
    (``toptraj.planners.collision.self_collision``; the search checks it always).

    Every answer holds the requested limits on a dense resampling within ``LIMIT_TOLERANCE``
    (with a positive limit margin, strictly within the limits): the gate refines the grid where
    a limit is exceeded and refuses an answer that still exceeds one.

    Raises:
        InvalidRequest: a ``dt`` that gives more than ``max_samples`` samples (the error names
            the smallest that fits), or what only the built path shows.
        InfeasiblePath: no timing can follow the path within the limits (says where, which
            joint and which limit).
        TimingFailed: the timing method failed.
        BudgetExceeded: the problem's deadline passed.
    """
    return run(problem)


def check(problem: Problem) -> None:
    """Refuse ``problem`` as ``plan`` would before any work, without planning it: its memory
    estimate against the cap (``toptraj.planners.runner.admission.admit``); ``build_problem``
    has validated the rest. For a caller that queues the problem to plan it later.

    Raises:
        TooLarge: the grid asked for does not fit (the largest that does is named).
        OverMemory: a search's graph does not fit its allowance.
    """
    admit(problem)
