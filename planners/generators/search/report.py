"""What a global search tells of its work (``toptraj.planners.generators.search.generator``,
Jeong & Lee sections 2.3 to 2.6): the branch and bound's statistics, the tubes' best grid paths
and the one followed, the region searched, the obstacle shadows, each tube's local optimization
and the final timing."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.generators.search.local_outcome import LocalOptimum
from toptraj.planners.generators.search.outcome import GridPath, SearchStatistics
from toptraj.planners.problem.methods import Report


@dataclass(frozen=True)
class LocalReport:
    """One tube's local optimization (section 2.6).

    Attributes:
        grid_time: The time t4 (s) of the tube's best grid path.
        seed_time: The exact duration (s) of the spline fitted to it (``inf`` when no timing
            can follow it).
        time: The optimized path's exact duration (s).
        control_points: Control points of each round.
        round_times: Each round's exact duration (s; ``inf`` where none).
        evaluations: Objective evaluations in all.
        stopped: Why the rounds stopped (``LocalStatistics.stopped``).
        wall_s: Seconds it took.
    """

    grid_time: float
    seed_time: float
    time: float
    control_points: tuple[int, ...]
    round_times: tuple[float, ...]
    evaluations: int
    stopped: str
    wall_s: float

    @classmethod
    def of(cls, grid_time: float, local: LocalOptimum) -> LocalReport:
        """The report of ``local``, the optimum of a tube whose best grid path takes ``grid_time`` s."""
        stats = local.statistics
        return cls(
            grid_time=grid_time, seed_time=stats.seed_duration, time=local.duration,
            control_points=tuple(r.control_points for r in stats.rounds), round_times=tuple(r.duration for r in stats.rounds),
            evaluations=stats.evaluations, stopped=stats.stopped, wall_s=stats.wall_s,
        )


@dataclass(frozen=True)
class SearchReport(Report):
    """A search's account.

    Attributes:
        statistics: What the branch and bound did.
        tube_radius: D_max (joint units).
        tubes: The best grid path of each tube, best first.
        chosen_tube: The index in ``tubes`` of the tube whose path is returned.
        low, high: The corners (n_dof,) of the region of joint space searched.
        shadows: Planar two-joint arms among obstacles: the obstacle shadows
            (``toptraj.planners.generators.search.shadows``); else ``None``.
        local: Each optimized tube's local optimization, in the order of ``tubes``.
        final_time: The returned motion's duration (s), timed by phase_plane.
    """

    statistics: SearchStatistics
    tube_radius: float
    tubes: tuple[GridPath, ...]
    chosen_tube: int
    low: np.ndarray
    high: np.ndarray
    shadows: dict | None
    local: tuple[LocalReport, ...]
    final_time: float
