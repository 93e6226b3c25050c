"""Branch and bound over grid paths (Jeong & Lee sections 2.3 to 2.6, after Shiller & Dubowsky
1991).

A subset of grid paths is a partial path from the start: every completion of it. Its lower
bound is a bound on its fixed part (the curve up to the middle of its last edge) plus the
cost-to-go from there (``SearchProblem.h1``, ``h2``); the tests run cheapest first, each on
what survived the one before:

* t1 (eq. 2.6): lengths over V_max, plus the straight distance to the goal over V_max;
* t2 (eq. 2.7): the time on the velocity limit curve, plus the least such time to the goal;
* t3 (eq. 2.8): the time on the maximum-acceleration curve from rest under the velocity limit
  curve, plus the least t2 to the goal; on a complete path, the deceleration into rest too;
* t4: the phase-plane timing of a complete grid path.

The search is best-first: the subset with the least bound is refined (its next test) or
branched (its partial path extended by every admissible move: no grid point twice, no sharp
turn). A subset is discarded as soon as a test puts it above the upper bound t_u (section 2.5):
t_u = (1 + epsilon) t~ with t~ the best grid-path time at hand, first from a greedy dive along
the least t2 to the goal, and lowered with every better grid path found. Subsets still queued
when the least bound exceeds t_u are discarded by t_u. Every grid path within t_u is kept; each
tube of radius D_max around the best of them gives one candidate for the local optimization
(section 2.6), best first.
"""

from __future__ import annotations

import time

import numpy as np

from toptraj.planners.errors import InfeasiblePath, TimingFailed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.search import search_kernels as kernels
from toptraj.planners.generators.search.bounds import grid_path_time, path_time
from toptraj.planners.generators.search.graph import DEFAULT_OPTIONS, SearchOptions
from toptraj.planners.generators.search.node_table import NodeTable
from toptraj.planners.generators.search.outcome import GridPath, NoGridPath, SearchResult, SearchStatistics
from toptraj.planners.generators.search.problem import SearchProblem


class _Node:
    """A subset: the partial (or complete) path ending in ``state`` (``SearchProblem``), with
    the bounds of its fixed curve so far and the spans it is made of."""

    __slots__ = ("state", "edge", "g1", "g2", "g3", "x", "visited", "parent", "piece", "complete", "t3", "t4")

    def __init__(self, state, edge, g1, g2, g3, x, visited, parent, piece, complete=False) -> None:
        self.state, self.edge = state, edge
        self.g1, self.g2, self.g3, self.x = g1, g2, g3, x
        self.visited, self.parent, self.piece, self.complete = visited, parent, piece, complete
        self.t3 = self.t4 = None

    def pieces(self) -> list[int]:
        out, node = [], self
        while node is not None:
            if node.piece >= 0:
                out.append(node.piece)
            node = node.parent
        return out[::-1]

    def edges(self) -> list[int]:
        out, node = [], self
        while node is not None:
            if node.edge >= 0:
                out.append(node.edge)
            node = node.parent
        return out[::-1]


class _Search:
    def __init__(self, problem: SearchProblem, options: SearchOptions, deadline: Deadline, cap: float = np.inf, stop_at: float = np.inf):
        self.problem, self.options, self.deadline = problem, options, deadline
        graph = problem.graph
        self.goal_points = set(int(g) for g in graph.goals)
        self.t_u = cap
        self.stop_at = stop_at
        self.found: list[GridPath] = []
        self.timed: list[int] = []  # the spans of every grid path timed (a lazy problem checks them)
        self.stopped = ""  # what ended an incomplete search: "memory", "expansions" or "time"
        self.stats = SearchStatistics(
            graph=graph.kind,
            grid_points=len(graph.points),
            grid_edges=len(graph.edge_from),
            grid_shape=[len(axis) for axis in graph.axes],
            turns=len(problem.turn_in),
            removed_by_obstacles=problem.removed,
            points_blocked=problem.points_blocked,
            v_max=problem.bounds.v_max,
            prepare_s=problem.prepare_s,
        )

    # bounds -----------------------------------------------------------------------------------
    def _intervals(self, pieces: list[int]) -> np.ndarray:
        first = self.problem.pieces.first
        return np.concatenate([np.arange(first[p], first[p + 1]) for p in pieces])

    def points(self, node: _Node) -> np.ndarray:
        return self.points_of(node.edges())

    def points_of(self, edges: list[int]) -> np.ndarray:
        """The grid points (k, n_dof) of the path made of ``edges`` from the start."""
        graph = self.problem.graph
        return graph.points[np.concatenate(([graph.start], graph.edge_to[np.asarray(edges, dtype=int)]))]

    def t3_of(self, node: _Node) -> float:
        b = self.problem.bounds
        return float(path_time(self._intervals(node.pieces()), b.ds, b.p, b.q, b.r, b.cap_start, b.cap_end))

    def t4_of(self, points: np.ndarray) -> float:
        """t4 (s) of the grid path through ``points``; ``inf`` where no timing follows it."""
        self.stats.t4_evaluations += 1
        problem = self.problem
        try:
            return grid_path_time(points, problem.robot, problem.limits, problem.kinds)
        except (InfeasiblePath, TimingFailed):
            return np.inf

    def _lower_t_u(self, t4: float) -> None:
        self.t_u = min(self.t_u, (1.0 + self.options.upper_margin) * t4)

    def root(self) -> _Node:
        return _Node(-1, -1, 0.0, 0.0, 0.0, 0.0, 1 << int(self.problem.graph.start), None, -1)

    def starts(self):
        """The first moves: (state, edge, piece, ending) each."""
        for edge, state, direct in self.problem.start_moves:
            if state >= 0:
                yield state, edge, -1, -1
            elif direct >= 0:
                yield -1, edge, -1, direct

    def dive(self) -> None:
        """A first grid path along the least t2 to the goal, for a first t_u."""
        problem, b = self.problem, self.problem.bounds
        options = [(problem.h2[state] if state >= 0 else b.t2[ending], state, edge, piece, ending) for state, edge, piece, ending in self.starts()]
        node = self.root()
        for _ in range(len(problem.graph.points)):
            options = [item for item in options if np.isfinite(item[0]) and not node.visited >> int(problem.graph.edge_to[item[2]]) & 1]
            if not options:
                return
            _, state, edge, piece, ending = min(options)
            node = _Node(state, edge, 0.0, 0.0, 0.0, 0.0, node.visited | 1 << int(problem.graph.edge_to[edge]), node, piece)
            if ending >= 0:
                node = _Node(state, -1, 0.0, 0.0, 0.0, 0.0, node.visited, node, ending, complete=True)
                self.timed += node.pieces()
                self._lower_t_u(self.t4_of(self.points(node)))
                return
            options = [
                ((b.t2[p] + (b.t2[end] if end >= 0 else problem.h2[s])), s, int(problem.turn_out[s]), p, end)
                for s, p, end in problem.successors[state]
            ]

    def run(self) -> None:
        began = time.perf_counter()
        self.dive()
        tables = NodeTable(self.problem, self.t_u)
        for state, edge, piece, ending in self.starts():
            tables.child(0, state, edge, piece, ending)
        while True:
            status, index = tables.chunk(self.options.max_expansions)
            if status == kernels.FULL:
                if not tables.grow():
                    self.stats.complete, self.stopped = False, "memory"  # the node table is at its most bytes
                    break
            elif status == kernels.NEED_T4:
                self.timed += tables.pieces(index)
                tables.settle(index, self.t4_of(self.points_of(tables.edges(index))), self.options.upper_margin)
            elif status == kernels.FOUND:
                g1, g2, _, _, t3, t4 = tables.floats[index]
                self.found.append(GridPath(self.points_of(tables.edges(index)), float(t4), (float(g1), float(g2), float(t3))))
            elif status in (kernels.CHUNK, kernels.MAX_EXPANSIONS):
                self.stats.complete = status == kernels.CHUNK
                self.stopped = "" if self.stats.complete else "expansions"
            if status == kernels.DONE or not self.stats.complete:
                break
            self.deadline.check()
            if time.monotonic() > self.stop_at:
                self.stats.complete, self.stopped = False, "time"
                break
            if status == kernels.CHUNK and np.isfinite(tables.upper[0]):
                t_u = float(tables.upper[0])
                self.deadline.progress(
                    min(float(tables.out_key[0]) / t_u, 1.0),
                    f"search: branch and bound, {tables.counters[kernels.EXPANDED]} expanded, "
                    f"t~ {t_u / (1.0 + self.options.upper_margin):.4g} s",
                )
        tables.count_into(self.stats)
        self.t_u = float(tables.upper[0])
        self.stats.candidates = len(self.found)
        self.stats.best_grid_time = self.found[0].time if self.found else None
        self.stats.upper_bound = self.t_u
        self.stats.search_s = time.perf_counter() - began


def hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    """The Hausdorff distance (joint units) between two grid paths' points."""
    distance = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return float(max(distance.min(axis=1).max(), distance.min(axis=0).max()))


def select_tubes(candidates: list[GridPath], radius: float, count: int) -> list[GridPath]:
    """The best grid path, then the best outside the tubes of radius ``radius`` around those
    taken, and so on, at most ``count`` (section 2.6)."""
    taken: list[GridPath] = []
    for candidate in candidates:
        if len(taken) >= count:
            break
        if all(hausdorff(candidate.points, other.points) > radius for other in taken):
            taken.append(candidate)
    return taken


def branch_and_bound(
    problem: SearchProblem,
    options: SearchOptions | None = None,
    deadline: Deadline = NO_DEADLINE,
    cap: float = np.inf,
    allowance_s: float | None = None,
) -> SearchResult:
    """The best grid paths of ``problem`` (see the module docstring).

    Args:
        cap: A first upper bound (s): subsets whose lower bound exceeds it are discarded from
            the start (``global_search`` passes a multiple of another goal variant's best).
        allowance_s: Seconds the search may take; then it stops with the grid paths found so
            far (``statistics.complete`` false). ``None``: until its bounds end it.

    Raises:
        NoGridPath: no grid path from start to goal below ``cap`` can be followed (obstacles
            block every one, or no timing meets the limits along any), or none was found
            within ``allowance_s``.
        BudgetExceeded: ``deadline`` passed.
    """
    options = options or DEFAULT_OPTIONS
    stop_at = np.inf if allowance_s is None else time.monotonic() + allowance_s
    search = _Search(problem, options, deadline, cap, stop_at)
    search.run()
    timed = np.unique(np.asarray(search.timed, dtype=int))
    if not search.found:
        stats = search.stats
        if not stats.complete:
            raise NoGridPath(
                f"the search found no grid path within its {_STOPPED[search.stopped]} ({stats.expanded} partial paths expanded)",
                stats, timed, rule="search_incomplete", graph=problem.graph.kind, stopped=search.stopped,
            )
        below = f" faster than {cap:.4g} s" if np.isfinite(cap) else ""
        raise NoGridPath(
            f"the search found no grid path from start to goal{below} that keeps the clearance and the limits "
            f"({stats.grid_points} grid points, {stats.removed_by_obstacles} pieces of path removed by obstacles, "
            f"{stats.points_blocked} grid points blocked)",
            stats, timed, rule="no_grid_path", graph=problem.graph.kind, cap=cap,
        )
    scale = problem.graph.scale
    radius = options.tube_radius if options.tube_radius is not None else 3.0 * float(np.linalg.norm(scale))
    tubes = select_tubes(search.found, radius, max(1, options.tubes))
    return SearchResult(tuple(tubes), tuple(search.found), search.stats, radius, timed)


#: What ended an incomplete search (``_Search.stopped``), in a sentence.
_STOPPED = {"memory": "node table's memory", "expansions": "max_expansions", "time": "share of the time budget"}


def enumerate_grid_paths(problem: SearchProblem, deadline: Deadline = NO_DEADLINE, limit: int = 100_000) -> list[GridPath]:
    """Every grid path of ``problem`` (no loops, no sharp turns, usable spans) with its t4 and
    its bounds, best first: the exhaustive enumeration the branch and bound must agree with. At
    most ``limit`` paths."""
    search = _Search(problem, DEFAULT_OPTIONS, deadline)
    b = problem.bounds
    edge_to = problem.graph.edge_to
    out: list[GridPath] = []

    def visit(node: _Node, state: int, edge: int, piece: int, ending: int):
        if len(out) >= limit:
            return
        g1 = node.g1 + (b.t1[piece] if piece >= 0 else 0.0)
        g2 = node.g2 + (b.t2[piece] if piece >= 0 else 0.0)
        node = _Node(state, edge, g1, g2, 0.0, 0.0, node.visited | 1 << int(edge_to[edge]), node, piece)
        if ending >= 0:
            complete = _Node(state, -1, g1 + b.t1[ending], g2 + b.t2[ending], 0.0, 0.0, node.visited, node, ending, complete=True)
            out.append(GridPath(search.points(complete), search.t4_of(search.points(complete)), (float(complete.g1), float(complete.g2), search.t3_of(complete))))
            return
        deadline.check()
        for after, span, end in problem.successors[state]:
            target = int(edge_to[problem.turn_out[after]])
            if not node.visited >> target & 1:
                visit(node, after, int(problem.turn_out[after]), span, end)

    root = search.root()
    for state, edge, piece, ending in search.starts():
        visit(root, state, edge, piece, ending)
    out.sort(key=lambda item: item.time)
    return out
