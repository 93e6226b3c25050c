"""The second family of methods: motion generators, which find the motion itself (via points,
joints moving on their own, the collocation, the global search) and return a path with its
timing; and ``Timed``, what both families hand the runner.

Timing methods (``toptraj.planners.timing.base.TimingMethod``, ``family = "timing"``) time a
given path from its ``PathConstraints``; the runner builds the path, its stretches and their
constraints for them. A generator (``family = "generator"``) gets the whole ``Problem`` and an
``Execution``: its share of the deadline, and the runner's own given-path pipeline
(``time_path``: stretches, constraints, the limit gate) for the paths it finds, so that no
generator calls the gate's pipeline or the runner itself.
"""

from __future__ import annotations

import abc
import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Literal, NamedTuple, TypeVar

from toptraj.planners.checks.gate import TimedStretch
from toptraj.planners.errors import ToptrajError
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.execution.memory import method_grid_cap
from toptraj.planners.paths import GeometricPath
from toptraj.planners.timing.base import PathTiming, TimingMethod
from toptraj.planners.trajectory import SwitchingTimes
from toptraj.robots import JointLimits, Robot

if TYPE_CHECKING:
    from toptraj.planners.problem.problem import BoundaryStates, Problem

T = TypeVar("T")


class Report:
    """A generator's typed account of its work, carried to the answer as it is
    (``toptraj.planners.generators.collocation.report.CollocationReport``,
    ``toptraj.planners.generators.search.report.SearchReport``)."""


class Timed(NamedTuple):
    """A path with its timing, its stretches as they were timed and checked, and what to tell
    about it: what either family of methods hands the runner."""

    path: GeometricPath
    timing: PathTiming
    stretches: tuple[TimedStretch, ...]
    method: str
    notes: tuple[str, ...] = ()
    cost: float | None = None
    solver: Report | None = None
    search: Report | None = None
    switching_times: SwitchingTimes | None = None
    #: For a method that finds the motion itself (a free path): the estimated relative gap of
    #: its objective to the optimum of its own problem, and how it was estimated; ``None`` when
    #: the answer's accuracy is that of its path's timing (``toptraj.planners.runner.accuracy``).
    motion_gap: tuple[float | None, str] | None = None


#: The runner's given-path pipeline: (robot, path, method, grid intervals, boundary states,
#: duration, kinds, limits, deadline, threshold) -> Timed, each stretch between corners timed and
#: passed through the limit gate.
TimePath = Callable[
    [Robot, GeometricPath, TimingMethod, "int | None", "BoundaryStates", "float | None", tuple, JointLimits, Deadline, float], Timed
]


@dataclass(frozen=True)
class Execution:
    """What the runner lends a generator: its share of the deadline (budget, cancellation,
    progress), the given-path pipeline for the paths it finds, and the way to run a step that
    cannot check the deadline (``uninterruptible``). ``time_path`` is a module-level function,
    so an ``Execution`` crosses into a worker process.

    Attributes:
        isolate: Whether ``uninterruptible`` runs its step in a worker process killed at the
            deadline (``run_isolated``): the runner's choice, for a method whose capabilities
            say it is not ``interruptible``, under a deadline, outside a worker process (which
            is killed whole). Else the step runs inline.
    """

    deadline: Deadline
    time_path: TimePath
    isolate: bool = False

    def within(self, start: float, end: float, label: str = "") -> Execution:
        """The same execution for a part of the work (``Deadline.within``)."""
        return dataclasses.replace(self, deadline=self.deadline.within(start, end, label))

    def uninterruptible(self, function: Callable[..., T], *args: object, progress: bool = False, memory_bytes: int | None = None) -> T:
        """``function(*args)`` (a module-level function of plain, picklable arguments), in a
        worker process at a lower CPU priority when ``isolate``, else inline; with ``progress``,
        called with ``progress=report`` relayed to the deadline's progress. ``memory_bytes``:
        the most its process may grow by (``OverMemory`` beyond)."""
        from toptraj.planners.execution.isolated import LOW_PRIORITY, run_isolated  # only the methods that need it

        return run_isolated(
            function, *args, deadline=self.deadline, progress=progress, memory_bytes=memory_bytes, nice=LOW_PRIORITY,
            inline=not self.isolate,
        )


class MotionGenerator(abc.ABC):
    """A method that finds the motion itself and returns it timed.

    Its capabilities are read as a timing method's are (``kinds``, ``required_kinds``,
    ``two_waypoints_only``, ``continuous_acceleration``, ``bytes_per_interval_joint``,
    ``interruptible``, ``max_grid_intervals``); ``estimate``, ``allowance`` and ``refuse`` give
    the runner's memory admission what the generator holds besides its grid
    (``toptraj.planners.runner.admission``). ``timed_by`` is the timing method whose accuracy
    the answer states when the generator states none of its own (``Timed.motion_gap``).
    """

    family: ClassVar[Literal["generator"]] = "generator"
    name: str
    kinds: frozenset[str] = frozenset({"velocity", "acceleration", "torque"})
    required_kinds: frozenset[str] = frozenset()
    two_waypoints_only: bool = False
    continuous_acceleration: bool = False
    bytes_per_interval_joint: int = 2_300
    interruptible: bool = True
    #: The supporting points of the time law that shapes the motion, when it is a spline.
    supporting_points: int | None = None

    def max_grid_intervals(self, n_dof: int) -> int:
        """The most grid intervals the generator's paths are timed on, on ``n_dof`` joints."""
        return method_grid_cap(self.bytes_per_interval_joint, n_dof)

    def estimate(self, problem: Problem) -> int:
        """Bytes the generator holds besides the grid its path is timed on (the search's graph),
        estimated from the problem before any work; 0 by default."""
        return 0

    def allowance(self, problem: Problem) -> int:
        """Bytes the generator's options allow its own estimate beside the one cap (the search's
        ``memory_bytes``); 0 by default."""
        return 0

    def refuse(self, problem: Problem, room: int) -> ToptrajError | None:
        """Why the generator's own estimate does not fit in ``room`` bytes, with the largest
        setting that does (``None``: no setting of its own lowers it)."""
        return None

    @property
    @abc.abstractmethod
    def timed_by(self) -> TimingMethod:
        """The timing method that times the motion's path (for the answer's accuracy)."""

    @abc.abstractmethod
    def validate(self, problem: Problem) -> None:
        """Refuse a problem the generator does not serve (``InvalidRequest``), before any
        work."""

    @abc.abstractmethod
    def generate(self, problem: Problem, execution: Execution) -> Timed:
        """The motion of ``problem``, timed and through the limit gate."""
