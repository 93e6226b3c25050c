"""The coordination diagram of two arms (O'Donnell & Lozano-Pérez 1989, §3): the square of
their path parameters (s1, s2) in [0, 1]^2, on a grid of (M + 1) x (M + 1) nodes, with the
distance between the arms at every node and the region where they would come closer than the
clearance marked as an obstacle.

Between nodes the distance changes by at most the arms' motion over a grid step, the path length
their capsule points travel, which is estimated (``STEP_SAFETY`` times the capsules' chord
between nodes, ``bounds.motion_steps``), not known. A cell is free when the distance over it is
at least the clearance plus ``FINE_STEP`` by the bounds that estimate gives: from its four corners
and the steps (``bounds.cell_bounds``, the corners' mean minus half the motion), else, where
only that margin blocks it (its corners all clear), by the bounds of its refined sub-cells
(``bounds.refined_bounds``). A point (s1, s2) is free when its cell is, or when it lies on
a border (an arm at rest at its start or end) along a step found clear by the segment bound
(``bounds.edge_bounds``); a node is blocked unless every cell around it is free (the nodes the
quickest curve may pass). Since the steps are estimates, "free" here is no proof: the schedule
finally chosen is verified apart, at fine samples, with a strict bound
(``toptraj.planners.coordination.verify``), and that check is what the answer's clearance rests on.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from toptraj.planners.coordination.bounds import cell_bounds, edge_bounds, motion_steps, refined_bounds
from toptraj.planners.coordination.cell import Cell, CellArm, pair_distances
from toptraj.planners.errors import InvalidRequest, OverMemory
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline

#: Grid intervals along each path parameter.
GRID = 100
#: Margin (m) kept above the clearance by the blocked region, for the checks between samples.
FINE_STEP = 0.005
#: Memory (bytes) the distance grid may take at once: one row of nodes, every capsule pair.
MEMORY_CAP = 200_000_000


@dataclass(frozen=True)
class Diagram:
    """The coordination diagram on ``s`` (M + 1,): ``distance`` (M + 1, M + 1) between the
    arms at (s1[i], s2[j]) in m, ``blocked`` (M + 1, M + 1) the nodes not surrounded by free
    cells, the arms' motion bound over each grid step, ``step1`` and ``step2`` (M,), in m, and
    ``free`` (M, M) the cells found clear (default: those with four free corners) and
    ``edges``, the steps found clear along the four borders, where one arm rests at its start
    or end: s2 = 0 and s2 = 1 (each (M,) over s1), s1 = 0 and s1 = 1 (each (M,) over s2)."""

    s: np.ndarray
    distance: np.ndarray
    blocked: np.ndarray
    step1: np.ndarray
    step2: np.ndarray
    free: np.ndarray | None = None
    edges: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def region(self) -> np.ndarray:
        """The collision region's nodes (M + 1, M + 1): those no free cell touches (so a free
        cell has none of them at its corners)."""
        if self.free is None:
            return self.blocked
        open_ = np.pad(self.free, 1, constant_values=False)
        return ~(open_[:-1, :-1] | open_[1:, :-1] | open_[:-1, 1:] | open_[1:, 1:])

    def free_at(self, s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
        """Whether each point (s1, s2) (n,) lies in a free cell (closed: a point on the edge
        between cells counts in one of them) or on a border along a free step (``edges``)."""
        m = len(self.s) - 1
        i = np.clip(np.floor(np.asarray(s1) * m).astype(int), 0, m - 1)
        j = np.clip(np.floor(np.asarray(s2) * m).astype(int), 0, m - 1)
        if self.free is not None:
            s1, s2 = np.asarray(s1), np.asarray(s2)
            free = self.free[i, j]
            if self.edges is not None:
                low, high, first, last = self.edges
                free = free | ((s2 == 0.0) & low[i]) | ((s2 == 1.0) & high[i]) | ((s1 == 0.0) & first[j]) | ((s1 == 1.0) & last[j])
            return free
        b = self.blocked
        return ~(b[i, j] | b[i + 1, j] | b[i, j + 1] | b[i + 1, j + 1])


def arm_capsules(arm: CellArm, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arm's world capsules at path parameters ``s`` (n,): a, b (n, k, 3), radius (k,)."""
    return arm.capsules_at(arm.path.evaluate(s).q)


def check_ends(cell: Cell) -> None:
    """InvalidRequest when two arms are closer than the clearance at their starts (where no
    timing can help), naming the arms and the two links."""
    for a, b in itertools.combinations(range(len(cell.arms)), 2):
        first, second = cell.arms[a], cell.arms[b]
        distance, i, j = pair_distances(arm_capsules(first, np.zeros(1)), arm_capsules(second, np.zeros(1)))
        if distance[0] < cell.clearance:
            links = (first.link_names()[int(i[0])], second.link_names()[int(j[0])])
            shift = separating_shift(arm_capsules(first, np.zeros(1)), arm_capsules(second, np.zeros(1)), int(i[0]), int(j[0]),
                                     first.base_position, second.base_position, cell.clearance)
            raise InvalidRequest(
                f"arms[{b}]", None, rule="arms_collide_at_start", first=a, second=b, links=links,
                robots=(first.robot.name, second.robot.name), distance=float(distance[0]), clearance=cell.clearance,
                shift=None if shift is None else tuple(float(x) for x in shift),
                position=None if shift is None else tuple(float(x) for x in second.base_position + shift),
                detail=f"arms {a} and {b} are {distance[0]:.4g} m apart at their start, closer than the clearance {cell.clearance:g} m",
            )


#: Longest move of a base (m) searched for one that clears the other arm at the start.
MOST_SHIFT = 10.0


def separating_shift(
    first: tuple[np.ndarray, np.ndarray, np.ndarray], second: tuple[np.ndarray, np.ndarray, np.ndarray], i: int, j: int,
    first_base: np.ndarray, base: np.ndarray, clearance: float,
) -> np.ndarray | None:
    """A move (3,) in m of the second arm's base (at ``base``, m), to a position of whole
    millimetres, that puts every capsule of the second arm (``second``, at one configuration:
    a, b (1, k, 3), radius (k,)) at least ``clearance`` from the first's: the shortest (to 1 mm)
    in the horizontal direction from capsule ``i`` of the first arm to capsule ``j`` of the
    second (the two closest; else from the first base ``first_base`` to the second, else along
    x); ``None`` within ``MOST_SHIFT``. Moving a base translates its capsules."""
    a1, b1, _ = first
    a2, b2, r2 = second
    direction = 0.5 * (a2[0, j] + b2[0, j]) - 0.5 * (a1[0, i] + b1[0, i])
    horizontal = np.array([1.0, 0.0, 0.0])
    for candidate in (direction, np.asarray(base, dtype=float) - np.asarray(first_base, dtype=float)):
        if np.hypot(candidate[0], candidate[1]) > 1e-9:
            horizontal = np.array([candidate[0], candidate[1], 0.0])
            break
    unit = horizontal / np.linalg.norm(horizontal)

    def clear(shift: np.ndarray) -> bool:
        return bool(pair_distances(first, (a2 + shift, b2 + shift, r2))[0][0] >= clearance)

    found = next((t for t in np.arange(0.05, MOST_SHIFT + 0.05, 0.05) if clear(t * unit)), None)
    if found is None:
        return None
    low, high = found - 0.05, float(found)
    while high - low > 1e-3:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if clear(middle * unit) else (middle, high)
    for extra in range(5):  # a position of whole millimetres that still clears, checked as printed
        shift = np.round(base + (high + 1e-3 * extra) * unit, 3) - base
        if clear(shift):
            return shift
    return None


@dataclass(frozen=True)
class Measured:
    """What a diagram's free cells are found from, whatever the margin: the grid ``s`` (M + 1,),
    the two arms' capsules ``one`` and ``two`` at it (a, b (M + 1, k, 3), radius (k,)), the
    ``distance`` (M + 1, M + 1) between them in m and their motion bounds ``step1``, ``step2``
    (M,) in m (``bounds.motion_steps``)."""

    s: np.ndarray
    one: tuple[np.ndarray, np.ndarray, np.ndarray]
    two: tuple[np.ndarray, np.ndarray, np.ndarray]
    distance: np.ndarray
    step1: np.ndarray
    step2: np.ndarray


def measure(cell: Cell, grid: int = GRID, deadline: Deadline = NO_DEADLINE) -> Measured:
    """The distances and steps of the cell's first two arms on ``grid`` intervals per axis
    (memory checked first: one row of (grid + 1) nodes, k1 x k2 capsule pairs, about 40 arrays
    of 8 bytes)."""
    first, second = cell.arms[:2]
    s = np.linspace(0.0, 1.0, grid + 1)
    one, two = arm_capsules(first, s), arm_capsules(second, s)
    row_bytes = 40 * 8 * (grid + 1) * one[0].shape[1] * two[0].shape[1] * 3
    if row_bytes > MEMORY_CAP:
        raise OverMemory(f"the coordination diagram needs {row_bytes / 1e6:.0f} MB per row: use arms with fewer links")
    distance = np.empty((grid + 1, grid + 1))
    for i in range(grid + 1):
        deadline.check()
        distance[i] = pair_distances((one[0][i][None], one[1][i][None], one[2]), two)[0]
    return Measured(s, one, two, distance, motion_steps(one), motion_steps(two))


def coordination_diagram(
    cell: Cell, grid: int = GRID, deadline: Deadline = NO_DEADLINE, margin: float = FINE_STEP, measured: Measured | None = None
) -> Diagram:
    """The diagram of the cell's first two arms on ``grid`` intervals per axis, its free cells
    ``margin`` (m) above the clearance, from ``measured`` (``measure`` of this cell and grid)
    when given: another margin finds which cells are free again, not the distances."""
    first, second = cell.arms[:2]
    m = measured if measured is not None else measure(cell, grid, deadline)
    one, two, distance, step1, step2 = m.one, m.two, m.distance, m.step1, m.step2
    needed = cell.clearance + margin
    free = _free_cells(needed, (first, second), (distance, step1, step2), deadline)
    closed = np.pad(~free, 1, constant_values=False)  # a node is blocked unless every cell around it is free
    blocked = closed[:-1, :-1] | closed[1:, :-1] | closed[:-1, 1:] | closed[1:, 1:]
    edges = (
        edge_bounds(first, (two[0][:1], two[1][:1], two[2]), distance[:, 0], step1, needed) >= needed,
        edge_bounds(first, (two[0][-1:], two[1][-1:], two[2]), distance[:, -1], step1, needed) >= needed,
        edge_bounds(second, (one[0][:1], one[1][:1], one[2]), distance[0, :], step2, needed) >= needed,
        edge_bounds(second, (one[0][-1:], one[1][-1:], one[2]), distance[-1, :], step2, needed) >= needed,
    )
    return Diagram(s=m.s, distance=distance, blocked=blocked, step1=step1, step2=step2, free=free, edges=edges)


def _free_cells(needed: float, arms: tuple[CellArm, CellArm], coarse: tuple[np.ndarray, ...], deadline: Deadline) -> np.ndarray:
    """Which cells (M, M) are found ``needed`` (m) apart: by the bound from their
    corners, else, where every corner is clear, by the bound of their refined sub-cells
    (``bounds``)."""
    distance, step1, step2 = coarse
    free = cell_bounds(distance, step1, step2) >= needed
    corners = np.minimum(np.minimum(distance[:-1, :-1], distance[1:, :-1]), np.minimum(distance[:-1, 1:], distance[1:, 1:]))
    refine = np.argwhere(~free & (corners >= needed))
    if len(refine):
        bounds = refined_bounds(refine, arms, len(step1), needed, deadline)
        free[refine[:, 0], refine[:, 1]] = bounds >= needed
    return free


def widest_coordination(diagram: Diagram) -> tuple[float, int, int]:
    """The largest distance (m) any monotone coordination of the two arms keeps on the diagram's
    grid, from (0, 0) to (M, M) by steps of (1, 0), (0, 1) or (1, 1), and the node (i, j) where
    the coordination that keeps it comes closest: a maximin (bottleneck) path, by dynamic
    programming over the nodes, O(M^2)."""
    distance = diagram.distance
    n = distance.shape[0]
    widest = np.full((n, n), -np.inf)  # the largest least distance over the paths to each node
    closest = np.zeros((n, n, 2), dtype=np.int64)  # where that path comes closest
    for i in range(n):
        for j in range(n):
            came, at = (-np.inf, (i, j)) if i or j else (np.inf, (0, 0))
            for di, dj in ((1, 0), (0, 1), (1, 1)):
                if i >= di and j >= dj and widest[i - di, j - dj] > came:
                    came, at = widest[i - di, j - dj], tuple(closest[i - di, j - dj])
            if distance[i, j] <= came:
                came, at = distance[i, j], (i, j)
            widest[i, j], closest[i, j] = came, at
    i, j = closest[-1, -1]
    return float(widest[-1, -1]), int(i), int(j)
