"""The search graph of Jeong & Lee section 2.1 (after Shiller & Dubowsky 1991): joint space
tessellated into grid points, each joined to its neighbours

    x'_j = x_i + Lambda_j d,   j = 1 ... 3^n - 1                                        (2.1)

(Lambda_j diagonal with entries -1, 0, 1; d the grid steps), and the direction-augmented graph
over it: a node is a grid point together with the edge it was reached by, so that a move may
depend on the direction of arrival. Moves that turn by more than ``max_turn`` (sharp turns) are
not edges of the augmented graph, and a path never visits a grid point twice (no loops).

Start and goal are grid points: along each joint the step is chosen so that the goal lies a whole
number of steps from the start. A continuous joint (no position limits) may reach its goal one
revolution either way: its axis is unrolled over those revolutions, each goal variant a grid
point, so that the Geering elbow's -2 pi revolution is a path of the graph.

For arms with many joints the lattice's 3^n - 1 neighbours and m^n points are out of reach; the
same search then runs over a sparse graph, a roadmap of seeded random configurations in the
search region, each joined to its nearest neighbours (``roadmap_graph``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from toptraj.planners.errors import InvalidRequest, OutOfRange, TooLarge, WrongLength
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.execution.memory import DEFAULT_SEARCH_MEMORY
from toptraj.robots import Robot

#: Grid intervals per joint across the search region when a request names none, by joint count.
DEFAULT_CELLS = {1: 32, 2: 16, 3: 8}
#: Most grid points a lattice may have (beyond, the request gets 422 naming a coarser ``cells``).
MAX_LATTICE_POINTS = 20_000
#: Most points of a roadmap.
MAX_ROADMAP_POINTS = 2_000
#: Largest turn between two consecutive moves (degrees, in grid units) by graph kind.
DEFAULT_MAX_TURN = {"lattice": 45.0, "roadmap": 90.0}
#: Moves (or roadmap rows) handled between two deadline checks while building a graph.
CHECK_EVERY = 1_024
#: Joints beyond which ``graph = "auto"`` takes a roadmap.
LATTICE_MAX_JOINTS = 3


@dataclass(frozen=True)
class SearchOptions:
    """How to search (``timing.search`` of a request).

    Attributes:
        cells: Grid intervals per joint across the search region (one value for every joint, or
            one per joint); ``None``: ``DEFAULT_CELLS`` by joint count.
        margin: How far the search region reaches beyond the box of start and goal along every
            joint, as a multiple of the largest joint span from start to goal, within the
            joint limits.
        max_turn: Largest turn (degrees) between consecutive moves, measured in grid units;
            ``None``: ``DEFAULT_MAX_TURN`` of the graph kind. Moves that turn more are sharp.
        upper_margin: epsilon of the upper bound t_u = (1 + epsilon) t~ (section 2.5), relative:
            grid paths within it of the best are kept as candidates for the tubes.
        tube_radius: D_max (rad or m, joint-space distance between grid paths) of the tubes of
            section 2.6; ``None``: three grid steps.
        tubes: Most tubes (best grid paths of distinct regions) returned.
        graph: ``"lattice"``, ``"roadmap"`` or ``"auto"`` (a lattice up to ``LATTICE_MAX_JOINTS``).
        roadmap_points: Random configurations of a roadmap (besides start and goal).
        neighbors: Nearest neighbours each roadmap point is joined to.
        seed: Seed of the roadmap's random configurations.
        max_expansions: Most partial paths the branch and bound expands.
        memory_bytes: Most bytes the search may take by its estimate
            (``toptraj.planners.generators.search.memory``); set by the service, not by a request.
        lazy: Whether the spans' clearance is checked only where the search times a grid path
            (``toptraj.planners.generators.search.problem.build_problem``); ``None``: on a
            roadmap in ``global_search``, never in ``build_problem`` alone.
    """

    cells: tuple[int, ...] | None = None
    margin: float = 0.5
    max_turn: float | None = None
    upper_margin: float = 0.02
    tube_radius: float | None = None
    tubes: int = 3
    graph: str = "auto"
    roadmap_points: int = 150
    neighbors: int = 10
    seed: int = 0
    max_expansions: int = 200_000
    memory_bytes: int = DEFAULT_SEARCH_MEMORY
    lazy: bool | None = None


DEFAULT_OPTIONS = SearchOptions()


@dataclass(frozen=True)
class SearchGraph:
    """Grid points and the moves between them.

    Attributes:
        kind: ``"lattice"`` or ``"roadmap"``.
        points: Joint configurations of the grid points, shape (P, n_dof), rad or m (continuous
            joints unrolled).
        edge_from, edge_to: Each directed edge's grid points, shape (E,).
        start: Index of the start point.
        goals: Indices of the goal points (the goal and its revolution variants), shape (G,).
        scale: Joint units per grid unit, shape (n_dof,): turns are measured in q / scale.
        axes: For a lattice, the grid values of each joint; empty for a roadmap.
    """

    kind: str
    points: np.ndarray
    edge_from: np.ndarray
    edge_to: np.ndarray
    start: int
    goals: np.ndarray
    scale: np.ndarray
    axes: tuple[np.ndarray, ...] = ()

    @property
    def edge_vectors(self) -> np.ndarray:
        """q_to - q_from of every edge, shape (E, n_dof)."""
        return self.points[self.edge_to] - self.points[self.edge_from]

    def transitions(self, max_turn_deg: float, deadline: Deadline = NO_DEADLINE) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (e_in, e_out) of edges meeting at a grid point that is no goal, turning by at
        most ``max_turn_deg`` degrees (in grid units) and not straight back: the edges of the
        direction-augmented graph. Shapes (T,) each. ``deadline`` is checked every
        ``CHECK_EVERY`` edges."""
        directions = self.edge_vectors / self.scale
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        order = np.argsort(self.edge_from, kind="stable")
        starts = np.searchsorted(self.edge_from[order], np.arange(len(self.points) + 1))
        is_goal = np.zeros(len(self.points), dtype=bool)
        is_goal[self.goals] = True
        cosine = math.cos(math.radians(max_turn_deg)) - 1e-9
        ins, outs = [], []
        for counted, e_in in enumerate(np.flatnonzero(~is_goal[self.edge_to])):
            if counted % CHECK_EVERY == 0:
                deadline.check()
            point = self.edge_to[e_in]
            candidates = order[starts[point] : starts[point + 1]]
            keep = candidates[(directions[candidates] @ directions[e_in] >= cosine) & (self.edge_to[candidates] != self.edge_from[e_in])]
            ins.append(np.full(len(keep), e_in))
            outs.append(keep)
        if not ins:
            return np.empty(0, dtype=int), np.empty(0, dtype=int)
        return np.concatenate(ins), np.concatenate(outs)


def _goal_variants(robot: Robot, start: np.ndarray, goal: np.ndarray, revolutions: bool) -> np.ndarray:
    """The goal and, for continuous joints, the goal one revolution either way: (G, n_dof)."""
    continuous = np.flatnonzero(robot.continuous) if revolutions else np.empty(0, dtype=int)
    variants = []
    for shifts in itertools.product((0.0, -2.0 * np.pi, 2.0 * np.pi), repeat=len(continuous)):
        variant = goal.copy()
        variant[continuous] += shifts
        variants.append(variant)
    return np.array(variants)


def search_region(robot: Robot, start: np.ndarray, goal: np.ndarray, goals: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (n_dof,) of the region searched: the box of start and goals
    (revolution variants included), widened along every joint by ``margin`` times the largest
    joint span from start to goal, within the joint limits."""
    widest = float(np.abs(goal - start).max())
    if widest <= 0.0 and len(goals) == 1:
        raise InvalidRequest("goal", goal, rule="goal_is_start")
    if np.any(np.all(np.abs(goals - start) <= 1e-9, axis=1)):
        # Staying put reaches one of the goals allowed: every motion found would be slower.
        raise InvalidRequest("goal", goal, rule="goal_is_start_turned")
    reach = margin * (widest if widest > 0.0 else 1.0)
    low = np.minimum(start, goals.min(axis=0)) - reach
    high = np.maximum(start, goals.max(axis=0)) + reach
    return np.maximum(low, robot.limits.position_lower), np.minimum(high, robot.limits.position_upper)


def _cells(options: SearchOptions, n_dof: int) -> np.ndarray:
    if options.cells is None:
        return np.full(n_dof, DEFAULT_CELLS.get(n_dof, 4))
    cells = np.asarray(options.cells, dtype=int).ravel()
    if cells.size == 1:
        cells = np.full(n_dof, int(cells[0]))
    if cells.size != n_dof:
        raise WrongLength("search.cells", options.cells, cells.size, n_dof, rule="search_cells_length")
    if np.any(cells < 1) or np.any(cells > 1_000):
        raise OutOfRange("search.cells", cells.tolist(), 1, 1_000, rule="search_cells_out_of_range")
    return cells


def _axis(start: float, goals: np.ndarray, low: float, high: float, step: float, continuous: bool) -> np.ndarray:
    """Grid values of one joint: ``start`` plus whole steps within [low, high], with every goal
    value on the grid. A joint whose goal is a whole number of steps away keeps one step; a
    continuous joint whose goals differ by revolutions gets two steps per revolution (one from
    the start to the goal, one from the goal to the start one turn on) so that each variant lies
    on the grid."""
    targets = np.unique(goals)
    if not continuous or len(targets) == 1:
        span = float(np.max(np.abs(targets - start)))
        if span > 0.0:
            step = span / max(1, round(span / step))
        below = math.floor((start - low) / step + 1e-9)
        above = math.floor((high - start) / step + 1e-9)
        values = start + step * np.arange(-below, above + 1)
        distances = np.abs(targets - start) / step
        if np.any(np.abs(distances - np.round(distances)) > 1e-6):
            # several goal values (revolution variants of a joint not treated as continuous)
            return _revolution_axis(start, targets, low, high, step)
        return values
    return _revolution_axis(start, targets, low, high, step)


def _revolution_axis(start: float, targets: np.ndarray, low: float, high: float, step: float) -> np.ndarray:
    turn = 2.0 * np.pi
    ahead = float((targets[0] - start) % turn)
    if ahead < 1e-9 or turn - ahead < 1e-9:
        count = max(2, round(turn / step))
        offsets = turn * np.arange(count) / count
    else:
        first = max(1, round(ahead / step))
        second = max(1, round((turn - ahead) / step))
        offsets = np.concatenate([np.linspace(0.0, ahead, first + 1)[:-1], np.linspace(ahead, turn, second + 1)[:-1]])
    turns = np.arange(math.floor((low - start) / turn) - 1, math.ceil((high - start) / turn) + 2)
    values = (start + offsets[None, :] + turn * turns[:, None]).ravel()
    keep = (values >= low - 1e-9) & (values <= high + 1e-9)
    return np.sort(values[keep])


def goal_variants(robot: Robot, revolutions: bool) -> int:
    """How many goal points a search has: the goal and its revolution variants."""
    return 3 ** int(np.count_nonzero(robot.continuous)) if revolutions else 1


def lattice_axes(robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool) -> tuple[np.ndarray, ...]:
    """The grid values of each joint of the lattice of eq. (2.1) over the search region."""
    n = robot.dof
    goals = _goal_variants(robot, start, goal, revolutions)
    low, high = search_region(robot, start, goal, goals, options.margin)
    cells = _cells(options, n)
    steps = (high - low) / cells
    span = np.abs(goals - start).max(axis=0)
    # a joint that does not move gets the region's typical step
    steps = np.where(steps > 0.0, steps, np.max(steps))
    return tuple(
        _axis(start[j], goals[:, j], low[j], high[j], float(steps[j] if steps[j] > 0 else span[j] or 1.0), bool(robot.continuous[j]))
        for j in range(n)
    )


def lattice_graph(robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool) -> SearchGraph:
    """The tessellated position space of eq. (2.1) over the search region, each grid point joined
    to its 3^n - 1 neighbours."""
    n = robot.dof
    goals = _goal_variants(robot, start, goal, revolutions)
    axes = lattice_axes(robot, start, goal, options, revolutions)
    shape = tuple(len(axis) for axis in axes)
    total = math.prod(shape)
    if total > MAX_LATTICE_POINTS:
        raise TooLarge("search.cells", options.cells, total, MAX_LATTICE_POINTS, "grid points", rule="lattice_too_large", shape=shape)
    index = np.indices(shape).reshape(n, -1).T  # (P, n)
    points = np.column_stack([axes[j][index[:, j]] for j in range(n)])
    moves = np.array([m for m in itertools.product((-1, 0, 1), repeat=n) if any(m)])
    edge_from, edge_to = [], []
    for move in moves:
        target = index + move
        inside = np.all((target >= 0) & (target < np.array(shape)), axis=1)
        edge_from.append(np.flatnonzero(inside))
        edge_to.append(np.ravel_multi_index(tuple(target[inside].T), shape))
    start_index = _find(points, start, "start")
    goal_index = np.array([_find(points, g, "goal") for g in goals])
    typical = np.array([np.median(np.diff(axis)) if len(axis) > 1 else 1.0 for axis in axes])
    return SearchGraph(
        kind="lattice",
        points=points,
        edge_from=np.concatenate(edge_from),
        edge_to=np.concatenate(edge_to),
        start=start_index,
        goals=goal_index,
        scale=typical,
        axes=axes,
    )


def _find(points: np.ndarray, q: np.ndarray, what: str) -> int:
    distance = np.abs(points - q).max(axis=1)
    index = int(np.argmin(distance))
    if distance[index] > 1e-6:  # pragma: no cover - the axes are built through start and goals
        raise InvalidRequest(what, q, rule="off_the_grid", detail=f"the {what} is not on the search grid")
    return index


def roadmap_graph(
    robot: Robot, start: np.ndarray, goal: np.ndarray, options: SearchOptions, revolutions: bool, free: Callable[[np.ndarray], np.ndarray],
    deadline: Deadline = NO_DEADLINE,
) -> SearchGraph:
    """A sparse graph for arms with many joints: start, goals and ``options.roadmap_points``
    random configurations of the search region (seeded; those ``free`` refuses are drawn again,
    up to ten times as many draws), each joined both ways to its ``options.neighbors`` nearest
    points, distances measured in units of the region's span per joint.

    Args:
        free: ``free(q) -> mask`` for configurations (k, n_dof): whether each keeps the
            clearance from the obstacles.
        deadline: Checked between draws and between blocks of ``CHECK_EVERY`` rows of the
            distances, which are computed a block at a time (memory P x ``CHECK_EVERY``).
    """
    n = robot.dof
    goals = _goal_variants(robot, start, goal, revolutions)
    low, high = search_region(robot, start, goal, goals, options.margin)
    count = int(options.roadmap_points)
    if not 1 <= count <= MAX_ROADMAP_POINTS:
        raise OutOfRange("search.roadmap_points", count, 1, MAX_ROADMAP_POINTS, rule="grid_out_of_range")
    rng = np.random.default_rng(options.seed)
    found: list[np.ndarray] = []
    drawn = 0
    while sum(len(f) for f in found) < count and drawn < 10 * count:
        deadline.check()
        batch = low + (high - low) * rng.random((count, n))
        drawn += count
        found.append(batch[free(batch)])
    samples = np.concatenate(found)[:count] if found else np.empty((0, n))
    points = np.vstack([start, goals, samples])
    scale = np.where(high > low, high - low, 1.0) / max(count, 1) ** (1.0 / n)
    unit = points / scale
    k = max(1, min(int(options.neighbors), len(points) - 1))
    nearest = np.empty((len(points), k), dtype=int)
    for begin in range(0, len(points), CHECK_EVERY):
        deadline.check()
        rows = np.arange(begin, min(begin + CHECK_EVERY, len(points)))
        squared = ((unit[rows, None, :] - unit[None, :, :]) ** 2).sum(axis=2)
        squared[np.arange(len(rows)), rows] = np.inf
        nearest[rows] = np.argsort(squared, axis=1)[:, :k]
    joined = {(int(i), int(j)) for i in range(len(points)) for j in nearest[i]}
    joined |= {(j, i) for i, j in joined}
    pairs = sorted(joined)
    edge_from = np.array([i for i, _ in pairs], dtype=int)
    edge_to = np.array([j for _, j in pairs], dtype=int)
    return SearchGraph(
        kind="roadmap",
        points=points,
        edge_from=edge_from,
        edge_to=edge_to,
        start=0,
        goals=np.arange(1, 1 + len(goals)),
        scale=scale,
    )
