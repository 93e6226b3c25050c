"""The memory a search needs, estimated from its settings before any work, against a cap.

A search's memory is that of its spans of curve (``planners.search.pieces``): per span, its
control points, its samples and their derivatives at ``INTERVALS`` intervals, and the rows of
its bounds (``planners.search.bounds``), all proportional to the joint count n. The spans are
the pairs of consecutive turns of the direction-augmented graph, so their count K grows with
the cube of a node's degree:

* roadmap (``roadmap_graph``): K ~ C P k^3, with P the graph's points (roadmap points, start
  and goal variants) and k the neighbours. C measured (turns up to 90 degrees, seed 0):
  0.16-0.32 on ur5 for P from 50 to 2,000 and k from 5 to 50 (K from 1,030 at 50/5 to
  69,058,450 at 2000/50), 0.20-0.23 on panda, 0.28-0.31 on the two-joint Geering arm; taken as
  ``ROADMAP_SPANS`` = 0.35 up to 90 degrees and four times that beyond (a turn then admits up to
  twice as many moves, and a span is two turns).
* lattice (``lattice_graph``): every interior grid point has the same moves, so K is at most
  P sum_m sum_{m' within m} t(m'), t(m) the moves a move m may turn into (``max_turn``): an
  exact bound where no boundary cuts moves (the Geering arm's default lattice: 15,544 spans,
  bound 20,808).

Bytes per span: ``SPAN_BYTES_PER_JOINT`` n, from the peak RSS of ``build_problem`` and
``global_search`` on ur5 (n = 6) over the process's RSS before it: 590 MB for 33,956 spans
(150 roadmap points, 10 neighbours; 17.4 kB a span), 2,580 MB for 189,703 (150/20; 13.6 kB),
503 MB for 32,001 with a box obstacle (15.7 kB), 2,505 MB for 182,606 with it (13.7 kB); a
whole ``global_search`` at 150/10 peaked at 523 MB without the box and 503 MB with it. Taken
as 2,800 bytes per joint (16.8 kB a span on ur5), plus the roadmap's distance matrix
(3 P^2 eight-byte numbers, built row block by row block).

The estimate is conservative: ur5's default search (150 points, 10 neighbours) is estimated at
0.9 GB for a measured 0.52-0.59 GB peak. A search estimated above its cap is refused before it
starts (``check_search_memory``: ``OverMemory`` naming the setting and the largest value served
with the others unchanged); a worker process running one is also capped by the system
(``planners.isolated``, twice the estimate), so that an estimate that is too low is a clear
error rather than the system killing a process.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from planners.errors import OverMemory
from planners.search.graph import (
    DEFAULT_MAX_TURN,
    LATTICE_MAX_JOINTS,
    MAX_ROADMAP_POINTS,
    SearchOptions,
    goal_variants,
    lattice_axes,
)
from robots import Robot

#: C of K ~ C P k^3 for a roadmap whose turns reach at most 90 degrees (see the module).
ROADMAP_SPANS = 0.35
#: Bytes a span takes per joint (see the module).
SPAN_BYTES_PER_JOINT = 2_800
#: Bytes of the process's own bookkeeping of a search besides its spans.
BASE_BYTES = 32 * 2**20


def _graph_kind(robot: Robot, options: SearchOptions) -> str:
    if options.graph == "auto":
        return "lattice" if robot.dof <= LATTICE_MAX_JOINTS else "roadmap"
    return options.graph


def _max_turn(kind: str, options: SearchOptions) -> float:
    return options.max_turn if options.max_turn is not None else DEFAULT_MAX_TURN[kind]


def _lattice_spans_per_point(n_dof: int, max_turn: float) -> int:
    """sum_m sum_{m' within m} t(m') over the lattice's 3^n - 1 moves m (module docstring)."""
    moves = np.array([m for m in itertools.product((-1, 0, 1), repeat=n_dof) if any(m)], dtype=float)
    unit = moves / np.linalg.norm(moves, axis=1, keepdims=True)
    cosine = unit @ unit.T
    within = (cosine >= math.cos(math.radians(min(max(max_turn, 0.0), 180.0))) - 1e-9) & (cosine > -1.0 + 1e-9)
    turns = within.sum(axis=1)
    return int((within * turns[None, :]).sum())


def roadmap_spans(points: int, neighbors: int, max_turn: float) -> float:
    """Estimated spans of a roadmap of ``points`` graph points (start and goals included) each
    joined to ``neighbors`` others, turns of at most ``max_turn`` degrees: an upper bound of
    the measured counts (module docstring)."""
    k = max(2, min(neighbors, points - 1))
    return ROADMAP_SPANS * (1.0 if max_turn <= 90.0 else 4.0) * points * k**3


def roadmap_bytes(n_dof: int, points: int, neighbors: int, max_turn: float) -> int:
    """Estimated bytes of a roadmap search (``roadmap_spans``) on an ``n_dof``-joint arm."""
    return int(BASE_BYTES + roadmap_spans(points, neighbors, max_turn) * SPAN_BYTES_PER_JOINT * n_dof + 24 * points**2)


def lattice_bytes(n_dof: int, points: int, max_turn: float) -> int:
    """Estimated bytes of a lattice search over ``points`` grid points."""
    spans = points * _lattice_spans_per_point(n_dof, max_turn)
    return int(BASE_BYTES + spans * SPAN_BYTES_PER_JOINT * n_dof)


def search_spans(robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool) -> float:
    """Estimated spans of curve of a search with these settings (an upper bound)."""
    kind = _graph_kind(robot, options)
    if kind == "lattice":
        points = math.prod(len(axis) for axis in lattice_axes(robot, start, goal, options, revolutions))
        return float(points * _lattice_spans_per_point(robot.dof, _max_turn(kind, options)))
    points = int(options.roadmap_points) + 1 + goal_variants(robot, revolutions)
    return roadmap_spans(points, int(options.neighbors), _max_turn(kind, options))


def search_bytes(robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool) -> int:
    """Estimated peak bytes of ``global_search`` with these settings (before any work)."""
    kind = _graph_kind(robot, options)
    if kind == "lattice":
        points = math.prod(len(axis) for axis in lattice_axes(robot, start, goal, options, revolutions))
        return lattice_bytes(robot.dof, points, _max_turn(kind, options))
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


def check_search_memory(
    robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool, cap_bytes: int | None = None
) -> int:
    """The search's estimated bytes (``search_bytes``) when within ``cap_bytes`` (default
    ``options.memory_bytes``, itself ``DEFAULT_SEARCH_MEMORY`` unless set).

    Raises:
        OverMemory: the estimate exceeds the cap; the detail names the settings and the largest
            value of one of them served with the others unchanged.
        InvalidRequest: settings the graph refuses (``planners.search.graph``).
    """
    cap_bytes = options.memory_bytes if cap_bytes is None else cap_bytes
    need = search_bytes(robot, start, goal, options, revolutions)
    if need <= cap_bytes:
        return need
    n = robot.dof
    kind = _graph_kind(robot, options)
    max_turn = _max_turn(kind, options)
    about = f"about {need / 2**30:.3g} GiB, above the cap of {cap_bytes / 2**30:.3g} GiB per search"
    if kind == "lattice":
        axes = lattice_axes(robot, start, goal, options, revolutions)
        shape = " x ".join(str(len(axis)) for axis in axes)

        def lattice_fits(cells: int) -> bool:
            grid = lattice_axes(robot, start, goal, _with(options, cells=(cells,)), revolutions)
            return lattice_bytes(n, math.prod(len(axis) for axis in grid), max_turn) <= cap_bytes

        cells = _largest(lattice_fits, 1, 1_000)
        advice = (
            f"at most {cells} cells per joint are served" if cells is not None else "no lattice fits: use timing.search.graph 'roadmap'"
        )
        raise OverMemory(f"timing.search.cells gives a lattice of {shape} grid points on a {n}-joint arm, which needs {about}; {advice}")
    extra = 1 + goal_variants(robot, revolutions)
    points, neighbors = int(options.roadmap_points), int(options.neighbors)
    most_points = _largest(lambda p: roadmap_bytes(n, p + extra, neighbors, max_turn) <= cap_bytes, 1, MAX_ROADMAP_POINTS)
    most_neighbors = _largest(lambda k: roadmap_bytes(n, points + extra, k, max_turn) <= cap_bytes, 1, max(1, neighbors))
    served = []
    if most_points is not None:
        served.append(f"at most {most_points} roadmap points are served with {neighbors} neighbors")
    if most_neighbors is not None:
        served.append(f"at most {most_neighbors} neighbors with {points} roadmap points")
    raise OverMemory(
        f"timing.search.roadmap_points {points} with neighbors {neighbors} on a {n}-joint arm needs {about}; "
        + ("; ".join(served) if served else "lower timing.search.neighbors and roadmap_points")
    )


def _with(options: SearchOptions, **changes) -> SearchOptions:
    return dataclasses.replace(options, **changes)
