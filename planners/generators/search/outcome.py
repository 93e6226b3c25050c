"""What the branch and bound over grid paths (``toptraj.planners.generators.search.branch_and_bound``, Jeong & Lee
sections 2.3 to 2.6) answers: the grid paths it found with their times and bounds, the tubes
that seed the local optimization, what the search did, and the error when it found no grid
path at all.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from toptraj.planners.errors import InfeasiblePath


@dataclass(frozen=True)
class GridPath:
    """A grid path from start to goal: its grid points (k, n_dof), joint units, continuous
    joints unrolled (the last point is the goal, possibly one revolution away), its time t4
    (s), the phase-plane time of its curve (``toptraj.planners.generators.search.bounds.grid_path_curve``) on the
    grid of its pieces, and its bounds t1, t2, t3 (s)."""

    points: np.ndarray
    time: float
    bounds: tuple[float, float, float]


@dataclass
class SearchStatistics:
    """What the search did.

    Attributes:
        graph: ``"lattice"`` or ``"roadmap"``.
        grid_points, grid_edges: Size of the graph; ``grid_shape`` the lattice's points per
            joint (empty for a roadmap).
        turns: Edges of the direction-augmented graph (moves after a move).
        removed_by_obstacles: Pieces of curve removed as configuration-space obstacles, among
            those checked.
        spans_checked: Pieces of curve whose clearance was checked: all of a lattice's, those of
            the grid paths timed on a roadmap (checked lazily: ``build_problem``).
        searches: Branch and bounds over the graph: one more after each that timed a grid path
            through a span found blocked when checked.
        points_blocked: Grid points closer to an obstacle than the clearance.
        v_max: V_max of t1 (joint units / s; ``inf`` where no limit bounds the speed).
        expanded: Partial paths branched.
        generated: Subsets created (partial or complete paths).
        pruned: Subsets discarded by each test: t1, t2, t3, t4, and by t_u (queued ones whose
            bound the falling t_u passed).
        t4_evaluations: Complete grid paths timed by the phase-plane method.
        candidates: Grid paths found within t_u.
        best_grid_time: t~, the best grid path's time (s).
        upper_bound: t_u at the end (s).
        complete: Whether the search ended by its bounds (the best grid path is proven the best
            of the graph); false when ``max_expansions`` or its time allowance stopped it.
        prepare_s, search_s: Seconds building the problem and searching.
        goal_variants: Revolution variants of the goal searched, each with its own t_u.
    """

    graph: str
    grid_points: int
    grid_edges: int
    grid_shape: list[int]
    turns: int
    removed_by_obstacles: int
    points_blocked: int
    v_max: float
    expanded: int = 0
    generated: int = 0
    pruned: dict[str, int] = field(default_factory=lambda: {"t1": 0, "t2": 0, "t3": 0, "t4": 0, "t_u": 0})
    t4_evaluations: int = 0
    candidates: int = 0
    best_grid_time: float | None = None
    upper_bound: float | None = None
    complete: bool = True
    prepare_s: float = 0.0
    search_s: float = 0.0
    goal_variants: int = 1
    spans_checked: int = 0
    searches: int = 1


@dataclass(frozen=True)
class SearchResult:
    """The search's answer.

    Attributes:
        tubes: The best grid path of each tube of radius ``tube_radius`` (section 2.6), best
            first: the candidates for the local optimization. ``tubes[0]`` is the best grid
            path.
        candidates: Every grid path found within t_u, best first.
        statistics: What the search did.
        tube_radius: D_max (joint units).
        timed: The spans (indices into the problem's pieces) of every grid path the search
            timed, shape (m,).
    """

    tubes: tuple[GridPath, ...]
    candidates: tuple[GridPath, ...]
    statistics: SearchStatistics
    tube_radius: float
    timed: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=int))


class NoGridPath(InfeasiblePath):
    """No grid path was found: with its search's ``statistics`` (and ``rule``: why none, and
    the ``graph`` kind searched) and the spans of the grid paths it timed (``timed``, a tuple of
    ``SearchResult.timed``'s indices)."""

    statistics: SearchStatistics

    def __init__(self, detail: str, statistics: SearchStatistics, timed: np.ndarray | None = None, **facts: Any):
        super().__init__(detail, statistics=statistics, **facts)
        self.timed = () if timed is None else tuple(int(span) for span in timed)
