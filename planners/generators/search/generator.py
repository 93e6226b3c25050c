"""``Search``, the motion generator of the global search among obstacles (Jeong & Lee
section 2): the best grid path of each tube, then each one's local optimization (section 2.6)
within its share of the budget; the fastest optimized path that keeps the clearance is timed by
phase_plane through the limit gate (the runner's given-path pipeline, ``Execution.time_path``).
The grid path's own curve stands in where its optimization finds nothing.

The search's memory is estimated from its settings (``estimate``, ``toptraj.planners.generators.search.memory``)
and admitted by the runner before any work (``OverMemory`` beyond ``timing.search.memory_bytes``). Under a deadline the whole search runs in
a worker process (``Execution.uninterruptible``, ``toptraj.planners.execution.isolated``) at a lower
CPU priority, its address space capped at ``SEARCH_MEMORY_ROOM`` times the estimate:
killed when the budget is spent or the caller cancels, its memory gone with it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.collision import check_clearance
from toptraj.planners.collision.self_collision import check_self_collision
from toptraj.planners.errors import Conflicting, InfeasiblePath, NotServed, OverMemory
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.generators.search.curve import GridSplinePath
from toptraj.planners.generators.search.graph import DEFAULT_OPTIONS, SearchOptions
from toptraj.planners.generators.search.local import optimize_locally
from toptraj.planners.generators.search.local_outcome import LocalOptimum
from toptraj.planners.generators.search.memory import over_memory, search_bytes
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.generators.search.problem import check_end
from toptraj.planners.generators.search.report import LocalReport
from toptraj.planners.paths import GeometricPath
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import Execution, MotionGenerator, Timed, TimePath
from toptraj.planners.problem.path_checks import moving_velocity
from toptraj.planners.problem.problem import BoundaryStates, Problem
from toptraj.planners.timing.base import TimingMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.robots import JointLimits, Robot

#: A search's worker process may grow its address space by this multiple of its memory
#: estimate, plus ``SEARCH_MEMORY_SLACK`` (the solver stacks' arenas and libraries' own
#: mappings): beyond, ``MemoryError`` there, answered as ``OverMemory``.
SEARCH_MEMORY_ROOM = 2
SEARCH_MEMORY_SLACK = 2**30


class Search(MotionGenerator):
    """Global search of path and timing among obstacles, with ``options`` (``None``: the
    defaults, ``DEFAULT_OPTIONS``)."""

    name = "search"
    kinds = frozenset({"velocity", "acceleration", "torque"})
    #: The whole search runs in its worker process under a deadline.
    interruptible = False

    def __init__(self, options: SearchOptions | None = None):
        self.options = options or DEFAULT_OPTIONS

    @property
    def timed_by(self) -> TimingMethod:
        return PhasePlaneMethod()

    def validate(self, problem: Problem) -> None:
        motion = problem.motion
        if not isinstance(motion, FreeMotion):
            raise NotServed("method", "search", "search", rule="search_needs_free_path")
        moving = moving_velocity(motion.start_velocity) is not None or moving_velocity(motion.end_velocity) is not None
        if moving or problem.duration is not None:
            raise Conflicting("method", "search", ("boundary", "duration"), rule="search_from_rest")
        for name, q in (("start", motion.start), ("goal", motion.goal)):
            check_end(problem.robot, name, q, list(problem.obstacles), problem.clearance)

    def estimate(self, problem: Problem) -> int:
        """The bytes of the search's graph (``toptraj.planners.generators.search.memory``); 0 for
        an end outside the joint range, which the search itself refuses with the joint named."""
        spec, robot = problem.motion, problem.robot
        assert isinstance(spec, FreeMotion)  # validated
        if robot.outside_position_limits(spec.start) is not None or robot.outside_position_limits(spec.goal) is not None:
            return 0
        return search_bytes(robot, spec.start, spec.goal, self.options, spec.revolutions)

    def allowance(self, problem: Problem) -> int:
        """The search's own memory setting (``SearchOptions.memory_bytes``)."""
        return int(self.options.memory_bytes)

    def refuse(self, problem: Problem, room: int) -> OverMemory:
        """The graph over ``room`` bytes, with the largest roadmap or lattice that fits."""
        spec = problem.motion
        assert isinstance(spec, FreeMotion)  # validated
        return over_memory(problem.robot, spec.start, spec.goal, self.options, spec.revolutions, room)

    def generate(self, problem: Problem, execution: Execution) -> Timed:
        """The search's motion: the whole search is its uninterruptible step, in a worker process
        under a budget (``Execution.uninterruptible``); its memory was admitted by the runner
        (``estimate``)."""
        spec, robot, deadline = problem.motion, problem.robot, execution.deadline
        assert isinstance(spec, FreeMotion)  # validated
        need = self.estimate(problem)
        work = _Work(robot, spec, problem.boundary, problem.grid, self.options, problem.kinds, problem.limits, problem.threshold,
                     problem.obstacles, problem.clearance, execution.time_path)
        try:
            return execution.uninterruptible(
                _searched, work, deadline.end, deadline.budget_s, progress=True, memory_bytes=SEARCH_MEMORY_ROOM * need + SEARCH_MEMORY_SLACK,
            )
        except OverMemory as error:
            raise OverMemory(
                f"the search needed more memory than its estimate of {need / 2**30:.3g} GiB allowed ({error.detail})",
                rule="search_over_estimate", estimate=need, cause=error.detail,
            ) from None


@dataclasses.dataclass(frozen=True)
class _Work:
    """What the search's worker process needs of the problem (no deadline: it gets its own)."""

    robot: Robot
    spec: FreeMotion
    boundary: BoundaryStates
    grid: int | None
    search: SearchOptions
    kinds: tuple[str, ...]
    limits: JointLimits
    threshold: float
    obstacles: tuple
    clearance: float
    time_path: TimePath


def _searched(work: _Work, end: float, budget_s: float | None, progress) -> Timed:
    """The search's work, in its worker process under the caller's deadline (ending at ``end``,
    ``time.monotonic()``), reporting to ``progress``."""
    deadline = Deadline.ending_at(end, budget_s, progress)
    timed = _search(work, deadline)
    # the constraints' re-evaluation holds this process's deadline: it does not travel back
    stretches = tuple(item._replace(constraints=dataclasses.replace(item.constraints, evaluate=None)) for item in timed.stretches)
    return timed._replace(stretches=stretches)


def _optimized_tubes(work: _Work, tubes, deadline: Deadline) -> tuple[list, list[str]]:
    """Each tube's best grid path optimized locally (section 2.6) within its share of what is
    left of the budget: (duration, tube index, optimum) for those that succeed, and why the
    others failed."""
    optimized, failures = [], []
    for index, tube in enumerate(tubes):
        remaining = deadline.remaining()
        # the rounds share what is left, three quarters of it (the rest: timing, gate, sampling)
        allowance = None if remaining is None else 0.75 * remaining / (len(tubes) - index)
        part = deadline.within(0.3 + 0.6 * index / len(tubes), 0.3 + 0.6 * (index + 1) / len(tubes))
        part.progress(0.0, f"local optimization of tube {index + 1} of {len(tubes)}")
        try:
            local = optimize_locally(work.robot, tube.points, work.limits, work.kinds, work.obstacles, work.clearance, part, allowance_s=allowance)
        except InfeasiblePath as error:
            failures.append(f"tube {index + 1}: {error.detail}")
            continue
        optimized.append((local.duration, index, local))
    return optimized, failures


def _search(work: _Work, deadline: Deadline) -> Timed:
    """The search's work under ``deadline``: the fastest candidate path that keeps the
    clearance and passes the gate, with the search's report."""
    robot, spec = work.robot, work.spec
    found = global_search(
        robot, work.limits, work.kinds, spec.start, spec.goal, work.search, spec.revolutions, work.obstacles, work.clearance,
        deadline.within(0.0, 0.3),
    )
    tubes = found.result.tubes
    optimized, failures = _optimized_tubes(work, tubes, deadline)
    plain = dataclasses.replace(work.boundary, start_velocity=None, end_velocity=None)
    candidates: list[tuple[GeometricPath, int, LocalOptimum | None]] = [
        (item.path, index, item) for _, index, item in sorted(optimized, key=lambda item: item[:2])
    ]
    candidates += [(GridSplinePath(tube.points), index, None) for index, tube in enumerate(tubes)]
    for path, index, optimum in candidates:
        try:
            if work.obstacles:
                check_clearance(path, robot, list(work.obstacles), work.clearance, deadline, explain=False)
            check_self_collision(path, robot, deadline=deadline)
            timed = work.time_path(robot, path, PhasePlaneMethod(), work.grid, plain, None, work.kinds, work.limits, deadline.within(0.9, 1.0), work.threshold)
        except InfeasiblePath as error:
            failures.append(f"tube {index + 1}{' (optimized)' if optimum is not None else ''}: {error.detail}")
            continue
        local = tuple(LocalReport.of(tubes[i].time, item) for _, i, item in sorted(optimized, key=lambda item: item[1]))
        report = found.report(index, local, timed.timing.duration)
        return timed._replace(method="search", notes=tuple(_notes(robot, spec, path, timed, optimum)), search=report)
    raise InfeasiblePath("no path the search found could be followed: " + "; ".join(failures))


def _notes(robot: Robot, spec: FreeMotion, path: GeometricPath, timed: Timed, optimum: LocalOptimum | None) -> list[str]:
    """What to tell of the path returned: joints that end a turn from the goal's angle, and how
    the local optimization ended."""
    end = path.evaluate(np.array([1.0])).q[0]
    notes = [*timed.notes]
    notes += [
        f"joint {robot.joint_names[j]!r} ends at {end[j]:.6g} rad, the goal's angle {turn:+.0f} revolution"
        for j in range(robot.dof)
        if (turn := round((end[j] - spec.goal[j]) / (2.0 * np.pi))) != 0
    ]
    if optimum is None:
        notes.append("the local optimization found no better path: the best grid path's own curve is returned")
    elif optimum.statistics.stopped == "allowance spent":
        notes.append(
            "the local optimization stopped when its share of the time budget was spent: a job with a larger "
            "budget_s may find a faster path"
        )
    return notes
