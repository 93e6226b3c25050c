"""Checks of a schedule at fine samples, independent of the diagram's grid: the arms' distance
along the motion (each arm's limits: ``toptraj.planners.coordination.limits``).

Clearance: samples in time dense enough that no point of either arm moves more than
``FINE_STEP`` between two; for every pair of arms, between samples the distance is at least the smaller of the two
sampled distances minus half the motion of the two arms (each point moves at most reach * sum |dq|,
``CellArm.reach``).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass

import numpy as np

from toptraj.planners.coordination.cell import Cell, pair_distances
from toptraj.planners.coordination.diagram import FINE_STEP
from toptraj.planners.coordination.timing import Schedule
from toptraj.planners.errors import OverMemory
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline

#: Samples of the first, coarse pass that measures the motion.
COARSE = 400
#: Most samples of a clearance check (each one a forward kinematics per arm; about 30 us per
#: sample for two ur5s, 3 s at the most).
MAX_SAMPLES = 100_000
#: Samples whose capsules and distances are held at once.
CHUNK = 5_000


@dataclass(frozen=True)
class PairClearance:
    """The smallest sampled distance (m) between two arms of the cell, ``arms`` = (a, b) (the
    pair with the smallest guaranteed distance), at time ``t`` (s) between link ``links[0]`` of
    arm a and ``links[1]`` of arm b; ``bound``, the smallest distance guaranteed between
    samples over every pair; ``samples`` checked."""

    distance: float
    t: float
    links: tuple[str, str]
    bound: float
    samples: int
    arms: tuple[int, int] = (0, 1)


def _motion(arms, states) -> np.ndarray:
    """A bound (m) on the motion of any point of ``arms`` between successive samples."""
    return sum(arm.reach() * np.abs(np.diff(q, axis=0)).sum(axis=1) for arm, (q, _, _) in zip(arms, states))


def _pair(cell: Cell, a: int, b: int, t: np.ndarray, states, capsules) -> PairClearance:
    """Arms a and b's distance at the samples ``t``, and the bound between them."""
    distance, i, j = pair_distances(capsules[a], capsules[b])
    bound = np.minimum(distance[:-1], distance[1:]) - _motion((cell.arms[a], cell.arms[b]), (states[a], states[b])) / 2.0
    worst = int(np.argmin(distance))
    links = (cell.arms[a].link_names()[int(i[worst])], cell.arms[b].link_names()[int(j[worst])])
    return PairClearance(float(distance[worst]), float(t[worst]), links, float(bound.min()), len(t), (a, b))


def schedule_clearance(cell: Cell, schedule: Schedule, deadline: Deadline = NO_DEADLINE) -> PairClearance:
    """The arms' distance along ``schedule`` at fine samples, every pair (module docstring),
    taken ``CHUNK`` samples at a time (the memory of a chunk's capsules and distances, whatever
    the count).

    Raises:
        OverMemory: more than ``MAX_SAMPLES`` samples are needed, saying into how many parts to
            split the motion.
    """
    coarse = schedule.states(cell, np.linspace(0.0, schedule.duration, COARSE + 1))
    count = math.ceil(float(_motion(cell.arms, coarse).sum()) / FINE_STEP) + 1
    if count > MAX_SAMPLES:
        parts = math.ceil(count / MAX_SAMPLES)
        raise OverMemory(
            f"checking the arms' clearance needs {count} samples (one for every {FINE_STEP * 1000:g} mm any point of "
            f"an arm moves), more than {MAX_SAMPLES}: split the motion into {parts} cells or more, each arm's path into "
            "as many parts (the waypoints where one part ends starting the next)",
            rule="clearance_samples", count=count, most=MAX_SAMPLES, parts=parts,
        )
    t = np.linspace(0.0, schedule.duration, max(count, COARSE) + 1)
    pairs: dict[tuple[int, int], PairClearance] = {}
    for start in range(0, len(t) - 1, CHUNK):
        deadline.check()
        piece = t[start : start + CHUNK + 1]  # the chunks share their ends: the bound spans every gap
        states = schedule.states(cell, piece)
        capsules = [arm.capsules_at(q) for arm, (q, _, _) in zip(cell.arms, states)]
        for a, b in itertools.combinations(range(len(cell.arms)), 2):
            found = _pair(cell, a, b, piece, states, capsules)
            held = pairs.get((a, b))
            pairs[a, b] = found if held is None else _joined(held, found)
    worst = min(pairs.values(), key=lambda pair: pair.bound)
    return dataclasses.replace(worst, samples=len(t))


def _joined(first: PairClearance, second: PairClearance) -> PairClearance:
    """One pair's clearance over two chunks of samples."""
    closest = first if first.distance <= second.distance else second
    return dataclasses.replace(closest, bound=min(first.bound, second.bound))
