"""Checks of a schedule at fine samples, independent of the diagram's grid: the arms' distance
along the motion (each arm's limits: ``toptraj.planners.coordination.limits``).

Clearance: samples in time dense enough that no point of either arm moves more than
``FINE_STEP`` between two; for every pair of arms, between samples the distance is at least the smaller of the two
sampled distances minus half the motion of the two arms (each point moves at most reach * sum |dq|,
``CellArm.reach``).
"""

from __future__ import annotations

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
#: Most samples of a clearance check (each one a forward kinematics per arm).
MAX_SAMPLES = 20_000


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
    """The arms' distance along ``schedule`` at fine samples, every pair (module docstring)."""
    coarse = schedule.states(cell, np.linspace(0.0, schedule.duration, COARSE + 1))
    count = math.ceil(float(_motion(cell.arms, coarse).sum()) / FINE_STEP) + 1
    if count > MAX_SAMPLES:
        raise OverMemory(f"checking the arms' clearance needs {count} samples, more than {MAX_SAMPLES}: shorten the paths")
    t = np.linspace(0.0, schedule.duration, max(count, COARSE) + 1)
    states = schedule.states(cell, t)
    capsules = [arm.capsules_at(q) for arm, (q, _, _) in zip(cell.arms, states)]
    pairs = []
    for a, b in itertools.combinations(range(len(cell.arms)), 2):
        deadline.check()
        pairs.append(_pair(cell, a, b, t, states, capsules))
    worst = min(pairs, key=lambda pair: pair.bound)
    return PairClearance(worst.distance, worst.t, worst.links, worst.bound, len(t), worst.arms)
