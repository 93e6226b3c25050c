"""``plan``: from a robot and a motion request to a timed trajectory with torques.

Data flow (DESIGN.md): the problem built and validated once (``build_problem``: the method of
either family, the limits, the motion) -> the runner (``run``): a timing method times the given
path (GeometricPath q(s) -> PathConstraints on a grid -> TimeScaling s(t), through the limit
gate), a motion generator finds the motion and times it -> samples, phase plane, peak
utilization and the stated accuracy.
"""

from __future__ import annotations

from toptraj.planners.collision import Obstacle
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.problem.build import DEFAULT_CLEARANCE, MAX_SAMPLES, build_problem
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.problem import Sampling
from toptraj.planners.problem.requests import Timing, WaypointPath
from toptraj.planners.results import PlannedTrajectory
from toptraj.planners.runner.choice import method_for
from toptraj.planners.runner.run import run
from toptraj.robots import Robot


def plan(
    robot: Robot,
    path_spec: WaypointPath | CartesianLine | FreeMotion,
    timing: Timing = Timing(),
    dt: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
    max_samples: int = MAX_SAMPLES,
    exact_period: bool = False,
    obstacles: tuple[Obstacle, ...] = (),
    clearance: float = DEFAULT_CLEARANCE,
    self_collision: bool = False,
) -> PlannedTrajectory:
    """Plan the timed trajectory of ``robot`` along ``path_spec``, sampled every ``dt`` seconds
    into at most ``max_samples`` samples. With ``exact_period`` the samples lie on whole periods
    ``dt``, the final state included: the motion is slowed uniformly to end on one
    (``toptraj.planners.trajectory.sample_trajectory``); ``duration`` stays the planned (optimal) one
    and ``sampled_duration`` is the samples' last instant. With ``obstacles`` (world frame),
    every link keeps ``clearance`` (m) from them along the path (``toptraj.planners.collision``), and
    the answer carries the smallest distance found. With ``self_collision`` no two links of the
    arm touch along the path (``toptraj.planners.collision.self_collision``; the search checks it
    always).

    Every answer holds the requested limits on a dense resampling within ``LIMIT_TOLERANCE``
    (with ``timing.limit_margin`` > 0, strictly within the limits): the gate refines the grid
    where a limit is exceeded and refuses an answer that still exceeds one.

    Raises:
        InvalidRequest: malformed input (the message names the field), or a ``dt`` that gives
            more than ``max_samples`` samples (the message names the smallest that fits).
        InfeasiblePath: no timing can follow the path within the limits (says where, which
            joint and which limit).
        TimingFailed: the timing method failed.
        BudgetExceeded: ``deadline`` passed.
    """
    problem = build_problem(
        robot, path_spec, method_for(timing, path_spec), timing, sampling=Sampling(dt, max_samples, exact_period),
        obstacles=obstacles, clearance=clearance, deadline=deadline, self_collision=self_collision,
    )
    return run(problem)
