"""The memory a search needs, estimated from its settings before any work, against a cap.

A search's memory is that of its spans of curve (``toptraj.planners.generators.search.pieces``): per span, its
control points, its samples and their derivatives at ``INTERVALS`` intervals, and the rows of
its bounds (``toptraj.planners.generators.search.bounds``), all proportional to the joint count n. The spans are
the pairs of consecutive turns of the direction-augmented graph, so their count K grows with
the cube of a node's degree:

* roadmap (``roadmap_graph``): K ~ C P k^3, with P the graph's points (roadmap points, start
  and goal variants) and k the neighbours. C measured (turns up to 90 degrees, seed 0):
  0.16-0.32 on ur5 for P from 50 to 2,000 and k from 5 to 50 (K from 1,030 at 50/5 to
  69,058,450 at 2000/50), 0.20-0.23 on panda, 0.28-0.31 on the two-joint Geering arm; taken as
  ``ROADMAP_SPANS`` = 0.35 up to 90 degrees and four times that beyond (a turn then admits up to
  twice as many moves, and a span is two turns).
* lattice (``lattice_graph``): counted from the shape (``lattice_spans``): every chain of
  three moves, each turning into the next, at every grid point from which it stays on the
  grid; 15,792 for the Geering arm's default lattice (15,544 built), 63,900 at 32 cells
  (63,726), 198,656 for the three-joint lattice of ``benchmarks/search_growth.py`` at 8 cells
  (197,484).

Bytes per span: ``SPAN_BYTES_PER_JOINT`` n, from the peak RSS of ``build_problem`` over the
process's RSS before it: on ur5 (n = 6) 590 MB for 33,956 spans (150 roadmap points, 10
neighbours; 17.4 kB a span), 2,580 MB for 189,703 (150/20; 13.6 kB), 503 MB for 32,001 with
a box obstacle (15.7 kB), 2,505 MB for 182,606 with it (13.7 kB), a whole ``global_search`` at
150/10 523 MB without the box and 503 MB with it; on the three-joint lattice 1,454 MB for
197,484 spans (7.4 kB, 2.5 kB a joint) and 459 MB for 56,446 (8.1 kB); on the Geering arm
272 MB for 63,726 (4.3 kB, 2.1 kB a joint). Taken as 2,800 bytes per joint, plus the
roadmap's distance matrix (3 P^2 eight-byte numbers, built row block by row block).

The estimate is conservative: ur5's default search (150 points, 10 neighbours) is estimated at
0.86 GiB for a measured 0.52-0.59 GB peak, the three-joint lattice's default at 1.59 GiB for
1.45 GB. A search estimated above its cap (``DEFAULT_SEARCH_MEMORY``, 2 GiB) is refused before
it starts (the runner's admission, ``over_memory``: ``OverMemory`` naming the setting and the largest value
served with the others unchanged); a worker process running one is also capped by the system
(``toptraj.planners.generators.search.generator``: twice the estimate and 1 GiB), so that an estimate that is too low
is a clear error rather than the system killing a process.

The branch and bound's subsets (``toptraj.planners.generators.search.node_table``, 112 bytes each) are
not in the estimate: their table stops growing at ``MAX_NODE_BYTES`` (128 MiB), which the
worker's 1 GiB above the estimate holds, and the search then stops as at ``max_expansions``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from toptraj.planners.errors import NotOneOf, OverMemory
from toptraj.planners.generators.search.graph import (
    DEFAULT_MAX_TURN,
    LATTICE_MAX_JOINTS,
    MAX_ROADMAP_POINTS,
    SearchOptions,
    goal_variants,
    lattice_axes,
)
from toptraj.planners.generators.search.problem import GRAPH_KINDS
from toptraj.robots import Robot

#: C of K ~ C P k^3 for a roadmap whose turns reach at most 90 degrees (see the module).
ROADMAP_SPANS = 0.35
#: Joints up to which a lattice's spans are counted exactly (``lattice_spans``).
EXACT_LATTICE_JOINTS = 4
#: Bytes a span takes per joint (see the module).
SPAN_BYTES_PER_JOINT = 2_800
#: Bytes of the process's own bookkeeping of a search besides its spans.
BASE_BYTES = 32 * 2**20


def _graph_kind(robot: Robot, options: SearchOptions) -> str:
    if options.graph not in GRAPH_KINDS:
        raise NotOneOf("search.graph", options.graph, GRAPH_KINDS, rule="unknown_graph")
    if options.graph == "auto":
        return "lattice" if robot.dof <= LATTICE_MAX_JOINTS else "roadmap"
    return options.graph


def _max_turn(kind: str, options: SearchOptions) -> float:
    return options.max_turn if options.max_turn is not None else DEFAULT_MAX_TURN[kind]


def _moves_within(n_dof: int, max_turn: float) -> tuple[np.ndarray, np.ndarray]:
    """The lattice's 3^n - 1 moves (N, n) and which pairs (m, m') a move may turn into (N, N)."""
    moves = np.array([m for m in itertools.product((-1, 0, 1), repeat=n_dof) if any(m)], dtype=float)
    unit = moves / np.linalg.norm(moves, axis=1, keepdims=True)
    cosine = unit @ unit.T
    within = (cosine >= math.cos(math.radians(min(max(max_turn, 0.0), 180.0))) - 1e-9) & (cosine > -1.0 + 1e-9)
    return moves, within


def lattice_spans(shape: tuple[int, ...], max_turn: float) -> float:
    """Spans of a lattice of ``shape`` grid points per joint: every chain of three moves
    (m1, m2, m3), each turning into the next, counted at every grid point p from which p,
    p + m1, p + m1 + m2 and p + m1 + m2 + m3 all lie on the grid (the product over the joints
    of the axis length less the chain's extent along it), plus the spans from the start and
    into the goal. Beyond ``EXACT_LATTICE_JOINTS`` joints (3^n - 1 moves), a bound: every point
    times sum_m sum_{m' within m} t(m'), t(m) the moves a move m may turn into."""
    n = len(shape)
    moves, within = _moves_within(n, max_turn)
    turns = within.sum(axis=1)
    ends = 2.0 * len(moves) * float(turns.max())  # spans from the start and into the goal, at most
    if n > EXACT_LATTICE_JOINTS:
        return math.prod(shape) * float((within * turns[None, :]).sum()) + ends
    length = np.array(shape, dtype=float)
    total = 0.0
    for middle in range(len(moves)):
        first, last = np.flatnonzero(within[:, middle]), np.flatnonzero(within[middle])
        a = moves[first][:, None, :]  # (F, 1, n)
        b = moves[middle][None, None, :]
        c = moves[last][None, :, :]  # (1, L, n)
        corners = np.stack(np.broadcast_arrays(np.zeros_like(a + c), a, a + b, a + b + c))  # (4, F, L, n)
        extent = corners.max(axis=0) - corners.min(axis=0)
        total += float(np.prod(np.maximum(length - extent, 0.0), axis=2).sum())
    return total + ends


def roadmap_spans(points: int, neighbors: int, max_turn: float) -> float:
    """Estimated spans of a roadmap of ``points`` graph points (start and goals included) each
    joined to ``neighbors`` others, turns of at most ``max_turn`` degrees: an upper bound of
    the measured counts (module docstring)."""
    k = max(2, min(neighbors, points - 1))
    return ROADMAP_SPANS * (1.0 if max_turn <= 90.0 else 4.0) * points * k**3


def roadmap_bytes(n_dof: int, points: int, neighbors: int, max_turn: float) -> int:
    """Estimated bytes of a roadmap search (``roadmap_spans``) on an ``n_dof``-joint arm."""
    return int(BASE_BYTES + roadmap_spans(points, neighbors, max_turn) * SPAN_BYTES_PER_JOINT * n_dof + 24 * points**2)


def lattice_bytes(shape: tuple[int, ...], max_turn: float) -> int:
    """Estimated bytes of a lattice search of ``shape`` grid points per joint."""
    return int(BASE_BYTES + lattice_spans(shape, max_turn) * SPAN_BYTES_PER_JOINT * len(shape))


def search_spans(robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool) -> float:
    """Estimated spans of curve of a search with these settings (an upper bound)."""
    kind = _graph_kind(robot, options)
    if kind == "lattice":
        shape = tuple(len(axis) for axis in lattice_axes(robot, start, goal, options, revolutions))
        return lattice_spans(shape, _max_turn(kind, options))
    points = int(options.roadmap_points) + 1 + goal_variants(robot, revolutions)
    return roadmap_spans(points, int(options.neighbors), _max_turn(kind, options))


def search_bytes(robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool) -> int:
    """Estimated peak bytes of ``global_search`` with these settings (before any work)."""
    kind = _graph_kind(robot, options)
    if kind == "lattice":
        shape = tuple(len(axis) for axis in lattice_axes(robot, start, goal, options, revolutions))
        return lattice_bytes(shape, _max_turn(kind, options))
    points = int(options.roadmap_points) + 1 + goal_variants(robot, revolutions)
    return roadmap_bytes(robot.dof, points, int(options.neighbors), _max_turn(kind, options))


def _largest(fits, low: int, high: int) -> int | None:
    """The largest v in [low, high] with ``fits(v)`` (fits monotone, true below), or None."""
    if not fits(low):
        return None
    while low < high:
        middle = (low + high + 1) // 2
        low, high = (middle, high) if fits(middle) else (low, middle - 1)
    return low


def over_memory(
    robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool, cap_bytes: int
) -> OverMemory:
    """Why a search whose estimate (``search_bytes``) exceeds ``cap_bytes`` is refused: the
    detail names the settings and the largest value of one of them served with the others
    unchanged (the runner's admission raises it, ``toptraj.planners.runner.admission``).

    Raises:
        InvalidRequest: settings the graph refuses (``toptraj.planners.generators.search.graph``).
    """
    need = search_bytes(robot, start, goal, options, revolutions)
    n = robot.dof
    kind = _graph_kind(robot, options)
    max_turn = _max_turn(kind, options)
    about = f"about {need / 2**30:.3g} GiB, above the cap of {cap_bytes / 2**30:.3g} GiB per search"
    if kind == "lattice":
        axes = lattice_axes(robot, start, goal, options, revolutions)
        shape = " x ".join(str(len(axis)) for axis in axes)

        def lattice_fits(cells: int) -> bool:
            grid = lattice_axes(robot, start, goal, _with(options, cells=(cells,)), revolutions)
            return lattice_bytes(tuple(len(axis) for axis in grid), max_turn) <= cap_bytes

        cells = _largest(lattice_fits, 1, 1_000)
        return OverMemory(
            f"a lattice of {shape} grid points on a {n}-joint arm needs {about}", rule="lattice_over_memory",
            field="search.cells", shape=shape, dof=n, estimate=need, cap=cap_bytes, largest=cells,
        )
    extra = 1 + goal_variants(robot, revolutions)
    points, neighbors = int(options.roadmap_points), int(options.neighbors)
    most_points = _largest(lambda p: roadmap_bytes(n, p + extra, neighbors, max_turn) <= cap_bytes, 1, MAX_ROADMAP_POINTS)
    most_neighbors = _largest(lambda k: roadmap_bytes(n, points + extra, k, max_turn) <= cap_bytes, 1, max(1, neighbors))
    return OverMemory(
        f"a roadmap of {points} points with {neighbors} neighbors on a {n}-joint arm needs {about}", rule="roadmap_over_memory",
        field="search.roadmap_points", points=points, neighbors=neighbors, dof=n, estimate=need, cap=cap_bytes,
        most_points=most_points, most_neighbors=most_neighbors,
    )


def _with(options: SearchOptions, **changes) -> SearchOptions:
    return dataclasses.replace(options, **changes)
