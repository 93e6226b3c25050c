"""Lower bounds on the distance between two arms over the cells of their coordination diagram
(``toptraj.planners.coordination.diagram``), from the distances at the cells' corners and the
arms' motion over a step.

If no point of arm 1's capsules travels a path longer than m1 over a step of s1, and none of
arm 2's longer than m2 over a step of s2 (the length of the path each point runs, not the
straight distance between its ends), the distance between the arms changes by at most m1 + m2
over a cell. Along an edge of s1 between corners at distances d00 and d10 the distance is then
at least max(d00 - m1 u, d10 - m1 (1 - u)) >= (d00 + d10 - m1) / 2 (the bound of
``toptraj.planners.generators.search.local_objective`` for a segment); between the two edges of
s1, at least the mean of the two edges' bounds minus m2 / 2. So over the cell:

    d >= max((d00 + d10 + d01 + d11) / 4 - (m1 + m2) / 2,  max(corners) - m1 - m2)

(capped by the smallest corner, in case the motion was underestimated). The path lengths m1, m2
are not known exactly: ``motion_steps`` estimates them as ``STEP_SAFETY`` times the capsules'
largest chord between the grid's samples, which holds for paths that bend little within a step
but is no proof. These bounds choose where the schedule may go; the schedule finally chosen is
checked on its own at fine samples (``toptraj.planners.coordination.verify``), so an
underestimated step cannot pass unnoticed into an answer. Cells whose bound is
low only because the steps are long (their corners all clear) are refined: each cut into
``REFINE`` x ``REFINE`` sub-cells with their own corner distances and steps, its bound the
smallest of theirs. Along the diagram's borders, where one arm rests at its start or end while
the other moves (an arm that waits), only the segment bound applies (``edge_bounds``), refined
likewise.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.coordination.cell import CellArm, pair_distances
from toptraj.planners.errors import OverMemory
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline

#: Sub-cells per side of a refined cell.
REFINE = 4
#: Times a cell is refined at most (its sub-cells down to 1 / REFINE ** LEVELS of it).
LEVELS = 3
#: Memory (bytes) one batch of refined corners may take (about 40 arrays of 8 bytes a pair).
BATCH_BYTES = 100_000_000
#: Factor on the capsules' displacement between grid nodes for their motion in between.
STEP_SAFETY = 1.5
#: Most corner distances the refinement computes in all (a cell's time budget besides).
MAX_CORNERS = 2_000_000

Capsules = tuple[np.ndarray, np.ndarray, np.ndarray]


def cell_bounds(distance: np.ndarray, step1: np.ndarray, step2: np.ndarray) -> np.ndarray:
    """The lower bound (m) over each cell (module docstring) from the corner distances
    ``distance`` (..., n1 + 1, n2 + 1) and the arms' steps ``step1`` (..., n1) and ``step2``
    (..., n2), m: shape (..., n1, n2)."""
    corners = (distance[..., :-1, :-1], distance[..., 1:, :-1], distance[..., :-1, 1:], distance[..., 1:, 1:])
    motion = step1[..., :, None] + step2[..., None, :]
    mean = (corners[0] + corners[1] + corners[2] + corners[3]) / 4.0 - motion / 2.0
    best = np.maximum(np.maximum(corners[0], corners[1]), np.maximum(corners[2], corners[3])) - motion
    low = np.minimum(np.minimum(corners[0], corners[1]), np.minimum(corners[2], corners[3]))
    return np.minimum(np.maximum(mean, best), low)


def motion_steps(capsules: Capsules) -> np.ndarray:
    """An estimate of the path length (m) the arm's capsule points travel between successive
    samples, from their world end points a, b (n, k, 3): (n - 1,). A capsule moved rigidly
    moves each point of its axis by a convex combination of its ends' displacements, so by at
    most the larger chord; ``STEP_SAFETY`` (1.5) times that chord stands for the path between
    the samples, longer than the chord where the motion bends: an estimate, not a bound."""
    a, b = capsules[0], capsules[1]
    ends = np.maximum(np.linalg.norm(np.diff(a, axis=0), axis=-1), np.linalg.norm(np.diff(b, axis=0), axis=-1))
    return STEP_SAFETY * ends.max(axis=1)


def _arm_at(arm: CellArm, grid: int, indices: np.ndarray) -> tuple[Capsules, np.ndarray, np.ndarray]:
    """The arm's capsules at the nodes ``indices`` of a grid of ``grid`` steps (only the
    distinct ones), where each index lands among them, and the arm's motion (m) over the step
    from each index to the next (inf where the next is not among them)."""
    used, at = np.unique(indices, return_inverse=True)
    capsules = arm.capsules_at(arm.path.evaluate(used / grid).q)
    step = np.full(len(used), np.inf)
    step[:-1] = np.where(np.diff(used) == 1, motion_steps(capsules), np.inf)
    return capsules, at, step


def _corner_distances(arms: tuple[CellArm, CellArm], grid: int, rows: np.ndarray, columns: np.ndarray, deadline: Deadline):
    """Distances (m) at the nodes (rows[n], columns[n]) of the grid of ``grid`` steps per axis
    (the arms' capsules at just those s), in batches within ``BATCH_BYTES``; and each arm's
    motion over the step from each node onwards, (n,) each."""
    (one, at1, step1), (two, at2, step2) = _arm_at(arms[0], grid, rows), _arm_at(arms[1], grid, columns)
    out = np.empty(len(rows))
    batch = max(1, BATCH_BYTES // (40 * 8 * 3 * one[0].shape[1] * two[0].shape[1]))
    for start in range(0, len(rows), batch):
        deadline.check()
        r, c = at1[start : start + batch], at2[start : start + batch]
        out[start : start + batch] = pair_distances((one[0][r], one[1][r], one[2]), (two[0][c], two[1][c], two[2]))[0]
    return out, step1[at1], step2[at2]


def _sub_cells(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fine node indices of ``cells`` (n, 2) cut into ``REFINE`` x ``REFINE``: rows and
    columns (n, R + 1, R + 1), and the sub-cells' own indices (n, R, R, 2) on the fine grid."""
    shape = (len(cells), REFINE + 1, REFINE + 1)
    sub = np.arange(REFINE + 1)
    rows = np.broadcast_to(cells[:, 0, None, None] * REFINE + sub[None, :, None], shape)
    columns = np.broadcast_to(cells[:, 1, None, None] * REFINE + sub[None, None, :], shape)
    return rows, columns, np.stack([rows[:, :-1, :-1], columns[:, :-1, :-1]], axis=-1)


def refined_bounds(
    cells: np.ndarray, arms: tuple[CellArm, CellArm], grid: int, needed: float, deadline: Deadline = NO_DEADLINE
) -> np.ndarray:
    """The bounds (m) over ``cells`` (n, 2) of indices (i, j) on the grid of ``grid`` steps,
    each cut into ``REFINE`` x ``REFINE`` sub-cells, and those below ``needed`` though their
    corners are clear cut again, ``LEVELS`` times in all (the arms' capsules and their motion over
    each fine step computed at the fine nodes used only). Shape (n,).

    Raises:
        OverMemory: more than ``MAX_CORNERS`` fine corners to compute.
    """
    out = np.full(len(cells), np.inf)
    owner, level_cells = np.arange(len(cells)), cells
    for _ in range(LEVELS):
        grid *= REFINE
        count = len(level_cells) * (REFINE + 1) ** 2
        if count > MAX_CORNERS:
            raise OverMemory(
                f"refining the coordination diagram needs {count} distances, more than {MAX_CORNERS}: use fewer or shorter arms"
            )
        rows, columns, sub = _sub_cells(level_cells)
        distance, step1, step2 = (
            x.reshape(rows.shape) for x in _corner_distances(arms, grid, rows.ravel(), columns.ravel(), deadline)
        )
        bound = cell_bounds(distance, step1[:, :-1, 0], step2[:, 0, :-1])
        low = np.minimum(
            np.minimum(distance[:, :-1, :-1], distance[:, 1:, :-1]), np.minimum(distance[:, :-1, 1:], distance[:, 1:, 1:])
        )
        again = (bound < needed) & (low >= needed)
        settled = np.where(again, np.inf, bound).min(axis=(1, 2))
        np.minimum.at(out, owner, settled)
        owner, level_cells = np.broadcast_to(owner[:, None, None], again.shape)[again], sub[again]
        if not len(level_cells):
            return out
    np.minimum.at(out, owner, -np.inf)  # still unsettled at the finest level: not found clear
    return out


def edge_bounds(moving: CellArm, still: Capsules, distance: np.ndarray, steps: np.ndarray, needed: float) -> np.ndarray:
    """Lower bounds (m) over each step of one border of the diagram, where one arm rests (at its
    start or end, capsules ``still``: a, b (1, k, 3), radius (k,)) and ``moving`` goes through
    the grid's s: from the distances at the nodes ``distance`` (M + 1,) and the moving arm's
    motion over each step ``steps`` (M,), (d_i + d_{i+1} - m) / 2 (module docstring); steps
    below ``needed`` though both ends are clear are cut into ``REFINE ** LEVELS`` sub-steps.
    Shape (M,)."""
    low = np.minimum(distance[:-1], distance[1:])
    bound = np.minimum((distance[:-1] + distance[1:] - steps) / 2.0, low)
    refine = np.flatnonzero((bound < needed) & (low >= needed))
    if len(refine):
        count = REFINE**LEVELS
        m = len(steps)
        s = ((refine[:, None] + np.arange(count + 1)[None, :] / count) / m).ravel()
        capsules = moving.capsules_at(moving.path.evaluate(np.clip(s, 0.0, 1.0)).q)
        fine = pair_distances(capsules, still)[0].reshape(len(refine), count + 1)
        jumps = motion_steps(capsules)
        motion = np.delete(jumps, np.arange(count, len(jumps), count + 1)).reshape(len(refine), count)  # within each step
        sub = np.minimum((fine[:, :-1] + fine[:, 1:] - motion) / 2.0, np.minimum(fine[:, :-1], fine[:, 1:]))
        bound[refine] = sub.min(axis=1)
    return bound
