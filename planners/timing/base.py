"""The timing side of a trajectory: ``PathTiming`` s(t) (a grid-based ``TimeScaling`` for the
time-optimal methods, time laws for the classical ones), and the interface every timing method
implements (read ``PathConstraints``, return a ``PathTiming``)."""

from __future__ import annotations

import abc
from dataclasses import dataclass, field
from functools import cached_property
from typing import ClassVar, Literal

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.execution.memory import method_grid_cap
from toptraj.planners.timing.state_kernels import grid_states

#: Largest estimated relative gap to the converged optimum that a time-optimal answer carries
#: without being refined further or, when it cannot be, without a warning that gives the figure
#: (``PathTiming.optimality_gap``; the policy in ``toptraj.planners.runner.accuracy``).
GAP_TARGET = 1e-3


@dataclass(frozen=True)
class Boundary:
    """Path speed (1/s) and acceleration (1/s^2) at the ends; ``None`` accelerations are free
    for the time-optimal methods and zero for the time laws."""

    sd_start: float = 0.0
    sd_end: float = 0.0
    sdd_start: float | None = None
    sdd_end: float | None = None


#: At rest at both ends, accelerations free: the default boundary.
AT_REST = Boundary()


@dataclass(frozen=True)
class DenseStates:
    """Path states for checking limits between samples, each of shape (n,): s, sd, sdd, and
    sddd (1/s^3) when the timing has a finite jerk; ``left`` marks states that belong to the
    interval ending at their s (the left-hand side of a corner of the path); ``interval``, for
    timings on a grid of s, the grid interval each state lies in (a refinement names those)."""

    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    sddd: np.ndarray | None
    left: np.ndarray
    interval: np.ndarray | None = None


@dataclass(frozen=True)
class Binding:
    """The limit that sets a minimal duration: its kind, joint and place along the path."""

    kind: str
    joint: str | None
    s: float


class PathTiming(abc.ABC):
    """s(t) on [0, duration], from s = 0 to s = 1."""

    # Read-only here: a subclass gives them as dataclass fields with a default, or as properties.
    @property
    def switch_points(self) -> tuple[tuple[float, str], ...]:
        """(s, kind) pairs a method found, for the response; none unless a method says so."""
        return ()

    @property
    def binding(self) -> Binding | None:
        """The limit that sets the duration, when the method knows it."""
        return None

    @property
    def optimality_gap(self) -> float | None:
        """Estimated relative distance of this timing's objective from the converged optimum of
        its method's problem (the duration for time-optimal methods, the cost for min_cost with
        a torque weight, a time law's duration against its own shortest), found independently of
        the solve (a second discretization, another method, a bound); ``None``: not estimated."""
        return None

    @property
    def gap_basis(self) -> str:
        """How ``optimality_gap`` was estimated, or why there is none; empty when unsaid."""
        return ""

    @property
    @abc.abstractmethod
    def duration(self) -> float:
        """Total time, in s."""

    @abc.abstractmethod
    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, sd and sdd at times ``t`` (shape (n,), clipped to [0, duration])."""

    @abc.abstractmethod
    def dense_states(self, points_per_interval: int = 3) -> DenseStates:
        """States dense enough to check every limit between samples; timings on a grid of s
        take ``points_per_interval`` states per grid interval, both ends included."""

    @abc.abstractmethod
    def speed_at(self, s: np.ndarray) -> np.ndarray:
        """Path speed sd (1/s) at the given values of s, for the phase-plane picture."""


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class TimeScaling(PathTiming):
    """A time scaling s(t) with piecewise-constant path acceleration.

    Between grid points s_i and s_i+1 the path acceleration is constant,
    u_i = (sd_i+1^2 - sd_i^2) / (2 (s_i+1 - s_i)), so x = sd^2 is linear in s (the usual
    discretization of the phase plane) and each interval takes
    dt_i = 2 (s_i+1 - s_i) / (sd_i + sd_i+1).

    Attributes:
        s: Grid, shape (K + 1,), from 0 to 1.
        sd: Path speed at the grid points, shape (K + 1,), in 1/s.
        switch_points: Optional (s, kind) pairs a method found, for the response.
        optimality_gap: Estimated relative distance of the duration (or cost) from the
            converged optimum (``PathTiming.optimality_gap``); ``None`` when not estimated.
        gap_basis: How it was estimated (``PathTiming.gap_basis``).
    """

    s: np.ndarray
    sd: np.ndarray
    switch_points: tuple[tuple[float, str], ...] = field(default=())
    optimality_gap: float | None = None
    gap_basis: str = ""

    def __post_init__(self) -> None:
        sd = np.asarray(self.sd)
        # NaN and -inf fail the first comparison, +inf the second.
        if sd.size and not (sd.min() >= 0.0 and sd.max() < np.inf):
            raise TimingFailed("the timing method returned a non-finite or negative path speed")
        if sd.size > 1 and (sd[:-1] + sd[1:]).min() <= 0.0:
            index = int(np.flatnonzero(sd[:-1] + sd[1:] <= 0.0)[0])
            raise TimingFailed(
                f"the timing method stops the motion between s = {self.s[index]:.4g} and "
                f"s = {self.s[index + 1]:.4g}"
            )

    @cached_property
    def sdd(self) -> np.ndarray:
        """Path acceleration of each interval, shape (K,), in 1/s^2 (computed once, read-only)."""
        sd, s = self.sd, self.s
        return _read_only((sd[1:] ** 2 - sd[:-1] ** 2) / (2.0 * (s[1:] - s[:-1])))

    @cached_property
    def t(self) -> np.ndarray:
        """Time at each grid point, shape (K + 1,), in s (computed once, read-only)."""
        s, sd = self.s, self.sd
        t = np.zeros(len(s))
        np.cumsum(2.0 * (s[1:] - s[:-1]) / (sd[:-1] + sd[1:]), out=t[1:])
        return _read_only(t)

    @property
    def duration(self) -> float:
        """Total time, in s."""
        return float(self.t[-1])

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, sd and sdd at times ``t`` (shape (n,), clipped to [0, duration])."""
        grid_t = self.t
        # np.minimum and np.maximum: np.clip's dispatch costs more than the clipping here.
        t = np.minimum(np.maximum(np.asarray(t, dtype=float), 0.0), grid_t[-1])
        interval = np.minimum(np.maximum(np.searchsorted(grid_t, t, side="right") - 1, 0), len(self.s) - 2)
        tau = t - grid_t[interval]
        sdd = self.sdd[interval]
        sd = self.sd[interval] + sdd * tau
        s = self.s[interval] + self.sd[interval] * tau + 0.5 * sdd * tau**2
        return np.minimum(s, self.s[interval + 1]), np.maximum(sd, 0.0), sdd

    def dense_states(self, points_per_interval: int = 3, reference: np.ndarray | None = None) -> DenseStates:
        """States evenly spaced in s within each grid interval, both ends included: a grid point
        is reached as the end of one interval (``left``) and the start of the next, each with
        its own sdd. Within an interval x = sd^2 is linear in s.

        Args:
            points_per_interval: States per interval of ``reference`` (both ends included).
            reference: A coarser grid whose resolution the states keep (the grid the path's
                constraints were built on, which a method may have refined): an interval of
                this timing gets states as far apart as ``points_per_interval`` per interval of
                ``reference`` would be, at least its two ends. ``None``: this timing's grid.
        """
        grid = np.empty(0) if reference is None else np.ascontiguousarray(reference, dtype=float)
        s, sd, sdd, left, interval = grid_states(
            np.ascontiguousarray(self.s, dtype=float), np.ascontiguousarray(self.sd, dtype=float),
            np.ascontiguousarray(self.sdd, dtype=float), grid, max(points_per_interval, 2),
        )
        return DenseStates(s=s, sd=sd, sdd=sdd, sddd=None, left=left, interval=interval)

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        x = np.interp(s, self.s, self.sd**2)
        return np.sqrt(np.maximum(x, 0.0))


class TimingMethod(abc.ABC):
    """A way to time a path: reads ``PathConstraints``, returns a ``PathTiming``.

    Attributes:
        family: ``"timing"``: the family of methods that time a given path (the other,
            ``"generator"``, finds the motion itself: ``toptraj.planners.problem.methods``).
        name: The ``timing.method`` name.
        kinds: The limit kinds the method can respect.
        takes_duration: Whether a requested duration is honoured.
        takes_acceleration_boundary: Whether boundary path accelerations are honoured.
        required_kinds: Limit kinds the method always applies, requested or not.
        two_waypoints_only: Whether the method times only a straight move between two states.
        continuous_acceleration: Whether the method's path acceleration is continuous, so that
            the jerk of its samples (by finite differences) is checked against a jerk limit too.
        absolute_tolerances: Whether the method's solver works with absolute tolerances, so
            that it needs path speeds of order one (``toptraj.planners.timing.scaled``).
        bytes_per_interval_joint: The method's memory per grid interval and joint (about
            1.3 kB for phase_plane, 2.3 kB for toppra, 9 kB for min_cost;
            ``benchmarks/budgets.py``): the runner admits a grid by it against the one memory
            cap (``toptraj.planners.execution.memory``).
        setup_intervals: The method's set-up time per solve (building its program), counted in
            grid intervals solved in the same time: a finer grid's solve is expected to take
            the last one's times (intervals + setup) / (last intervals + setup)
            (``toptraj.planners.checks.accuracy.finer_constraints``).
        interruptible: Whether the method checks its deadline between steps; one that cannot
            (a convex solver's single call) runs that step through ``Isolation`` (a worker
            process killed at the deadline) when the runner isolates the planning.
        supporting_points: For a time law replaced by its spline through this many points
            (``toptraj.planners.timing.laws.splines.SplineProfile``): the spline leaves and
            reaches rest, so the method takes no moving boundary. ``None`` otherwise.
        pointwise: Whether the method's speed at each grid point is bounded by the limits at and
            near that point (the phase plane and its kin), so that a stretch which no limit
            bounds has no answer (``toptraj.planners.problem.bounded``); a time law fits one
            duration to a whole stretch, which a limit anywhere on it bounds.
    """

    family: ClassVar[Literal["timing"]] = "timing"
    name: str
    kinds: frozenset[str] = frozenset({"velocity", "acceleration", "torque"})
    required_kinds: frozenset[str] = frozenset()
    takes_duration: bool = False
    takes_acceleration_boundary: bool = False
    two_waypoints_only: bool = False
    continuous_acceleration: bool = False
    absolute_tolerances: bool = False
    bytes_per_interval_joint: int = 2_300
    setup_intervals: int = 0
    interruptible: bool = True
    supporting_points: int | None = None
    pointwise: bool = True

    def max_grid_intervals(self, n_dof: int) -> int:
        """The most grid intervals the method serves on a robot with ``n_dof`` joints: its
        default grid is thinned to it, its refinements stay within it."""
        return method_grid_cap(self.bytes_per_interval_joint, n_dof)

    @abc.abstractmethod
    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> PathTiming:
        """Time the path of ``constraints`` between the ``boundary`` states, in ``duration``
        seconds when given and supported, else as fast as the method allows."""
