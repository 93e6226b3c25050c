"""The settings of the local optimization of a path among obstacles (``toptraj.planners.generators.search.local``,
Jeong & Lee §2.6) and what it answers: each round's result, the statistics, and the optimum
with its exact timing and clearance.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from toptraj.planners.collision.clearance import Clearance
from toptraj.planners.paths.bspline import BSplinePath
from toptraj.planners.timing.base import TimeScaling


@dataclass(frozen=True)
class LocalSettings:
    """How the local optimization runs.

    Attributes:
        first_control_points: Control points of the first round (>= 4).
        max_control_points: No round goes beyond this many control points.
        improvement: Rounds stop when the exact duration has improved by less than this
            fraction in ``patience`` successive rounds (a spline of few control points may be
            unable to follow the better path that more of them reach), and at once when a
            round does not improve it right after a round that did.
        patience: Successive rounds without improvement before the rounds stop.
        grid_intervals: Intervals of the uniform optimization grid; a power of two, so that it
            holds the dyadic knots (at least 8 intervals per knot interval are kept).
        obstacle_samples: Configurations, uniform in s, at which the distance penalty is taken
            (128: the Geering example's rounds are the same as on 256, ur5 and panda around a
            box end within 1e-5 s of theirs, and the penalty, 60 % of an objective evaluation
            on a six-joint arm, costs half).
        margin: Distance (m) the penalty keeps beyond the clearance.
        obstacle_weight: Weight (s/m) of the distance shortfall; ``range_weight`` (s/rad) of
            the excursion beyond a joint range.
        evaluations_per_variable: Nelder-Mead's budget of objective evaluations per round,
            per free variable.
        step: Size of Nelder-Mead's first simplex in a round, as a fraction of each joint's
            extent along the path (at least ``min_step`` rad or m).
    """

    first_control_points: int = 4
    max_control_points: int = 19
    improvement: float = 1e-3
    patience: int = 2
    grid_intervals: int = 512
    obstacle_samples: int = 128
    margin: float = 1e-3
    obstacle_weight: float = 100.0
    range_weight: float = 100.0
    evaluations_per_variable: int = 100
    step: float = 0.1
    min_step: float = 0.02


@dataclass(frozen=True)
class LocalRound:
    """One round: its ``control_points`` count, the ``objective`` (s, optimization grid, with
    penalties) of its best point, its exact ``duration`` (s), whether it passed the dense
    checks (``clear``) and its objective ``evaluations``."""

    control_points: int
    objective: float
    duration: float
    clear: bool
    evaluations: int


@dataclass(frozen=True)
class LocalStatistics:
    """``evaluations`` of the objective in all, the ``rounds``, the exact duration of the
    fitted seed (``seed_duration``, s, ``inf`` when no timing can follow it), why the rounds
    stopped (``stopped``: "converged", "most control points", "allowance spent") and the wall
    time (s)."""

    evaluations: int
    rounds: tuple[LocalRound, ...]
    seed_duration: float
    stopped: str
    wall_s: float

    @property
    def durations(self) -> tuple[float, ...]:
        """The exact duration (s) of each round."""
        return tuple(r.duration for r in self.rounds)


@dataclass(frozen=True)
class LocalOptimum:
    """The optimized path (a ``GeometricPath`` for the planner), its exact time-optimal
    ``duration`` (s) and ``timing``, the ``control`` points (k, n_dof) and ``interior`` knots,
    the ``clearance`` found by the dense check (``None`` without obstacles) and statistics."""

    path: BSplinePath
    duration: float
    timing: TimeScaling
    control: np.ndarray
    interior: np.ndarray
    clearance: Clearance | None
    statistics: LocalStatistics = field(repr=False)
