"""Three or more arms: prioritized planning (Erdmann & Lozano-Pérez, "On multiple moving
objects", Algorithmica 2, 1987): the arms taken in an order, each on its own time-optimal motion
started after the least delay (of ``DELAYS`` evenly up to the end of the arms before it) that
keeps it clear of every arm before it, checked on the pairwise coordination diagrams
(O'Donnell & Lozano-Pérez 1989: arm a and arm b at (s_a(t), s_b(t)) in the free part of their
diagram). Every order of the arms is tried (at most 4! = 24), the quickest kept.

Optimality loss, stated: an arm only waits at its start, it never slows or waits on its way,
and the N-dimensional coordination space (s_1, ..., s_N) is not searched; so the cell can take
longer than the best coordination of all the arms (by at most the wait a slowing on the way
would save). It is never slower than the slowest arm's own optimum and, when moving the arms one
after the other is free, never slower than that. Two arms are coordinated in full
(``toptraj.planners.coordination.coordinate``).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from toptraj.planners.coordination.cell import Cell, pair_distances
from toptraj.planners.coordination.diagram import Diagram, arm_capsules, coordination_diagram
from toptraj.planners.coordination.timing import Schedule, SoloMotion
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.timing.base import TimeScaling

#: Late starts tried per arm, evenly up to the end of the arms before it.
DELAYS = 64
#: Samples in time at which a delay is checked against the diagrams.
SAMPLES = 1_000


def pair_diagrams(cell: Cell, deadline: Deadline) -> dict[tuple[int, int], Diagram]:
    """The coordination diagram of every pair of arms (a, b), a < b (rows s_a)."""
    out = {}
    for a, b in itertools.combinations(range(len(cell.arms)), 2):
        out[(a, b)] = coordination_diagram(Cell((cell.arms[a], cell.arms[b]), cell.clearance, cell.kinds), deadline=deadline)
    return out


def _clear(diagrams: dict[tuple[int, int], Diagram], placed: dict[int, SoloMotion], arm: int, motion: SoloMotion) -> bool:
    """Whether ``arm`` on ``motion`` stays in the free part of its diagram with each placed arm."""
    end = max([motion.duration] + [other.duration for other in placed.values()])
    t = np.linspace(0.0, end, SAMPLES + 1)
    s = motion.at(t)[0]
    for other, placed_motion in placed.items():
        s_other = placed_motion.at(t)[0]
        if other < arm:
            free = diagrams[(other, arm)].free_at(s_other, s)
        else:
            free = diagrams[(arm, other)].free_at(s, s_other)
        if not free.all():
            return False
    return True


def _in_order(diagrams, solo: list[TimeScaling], order: tuple[int, ...], deadline: Deadline) -> Schedule | None:
    """The arms placed in ``order``, each at its least free delay; None when one finds none."""
    placed = {order[0]: SoloMotion(solo[order[0]])}
    for arm in order[1:]:
        deadline.check()
        horizon = max(motion.duration for motion in placed.values())
        for delay in np.linspace(0.0, horizon, DELAYS + 1):
            motion = SoloMotion(solo[arm], float(delay))
            if _clear(diagrams, placed, arm, motion):
                placed[arm] = motion
                break
        else:
            return None
    waits = [f"arms[{arm}] waits" for arm in order if placed[arm].delay > 0.0]
    kind = "simultaneous" if not waits else "prioritized: " + ", ".join(waits)
    return Schedule(tuple(placed[arm] for arm in range(len(solo))), kind)


def prioritized(cell: Cell, solo: list[TimeScaling], diagrams: dict[tuple[int, int], Diagram], deadline: Deadline) -> Schedule:
    """The quickest prioritized schedule over every order of the arms (module docstring).

    Raises:
        InfeasiblePath: no order lets every arm pass the others by waiting at its start.
    """
    found = [_in_order(diagrams, solo, order, deadline) for order in itertools.permutations(range(len(cell.arms)))]
    best = min((schedule for schedule in found if schedule is not None), key=lambda schedule: schedule.duration, default=None)
    if best is None:
        turns = [turn for pair in itertools.combinations(range(len(cell.arms)), 2) for turn in _blocked_turns(cell, diagrams, *pair)]
        cycle = () if turns else _precedence_cycle(diagrams, len(cell.arms))
        where = "; ".join(turn.said() for turn in turns) or " before ".join(f"arm {k}" for k in cycle)
        raise InfeasiblePath(
            "no order of the arms lets each pass the others by waiting at its start (an arm's path crosses where "
            f"another arm rests at its start or end){': ' + where if where else ''}: move a base apart, change a path "
            "or lower clearance",
            rule="no_order_of_arms", turns=tuple(turns), clearance=cell.clearance, cycle=cycle,
        )
    return best


def _orders(diagram: Diagram) -> tuple[bool, bool]:
    """Whether the first arm of a pair may go first (moving while the second rests at its
    start, then resting at its end while the second moves), and whether the second may."""
    s = diagram.s
    zeros, ones = np.zeros_like(s), np.ones_like(s)
    first = bool(diagram.free_at(s, zeros).all() and diagram.free_at(ones, s).all())
    second = bool(diagram.free_at(zeros, s).all() and diagram.free_at(s, ones).all())
    return first, second


def _precedence_cycle(diagrams: dict[tuple[int, int], Diagram], count: int) -> tuple[int, ...]:
    """Arms (indices) each of which can pass the next only by going first, the last the first
    again: why no order serves when every pair can take turns in some order. Empty when the
    pairs' orders leave no cycle."""
    before: dict[int, list[int]] = {k: [] for k in range(count)}
    for (a, b), diagram in diagrams.items():
        a_first, b_first = _orders(diagram)
        if a_first and not b_first:
            before[a].append(b)
        elif b_first and not a_first:
            before[b].append(a)
    for start in range(count):  # a depth-first walk back to the start
        stack: list[tuple[int, tuple[int, ...]]] = [(start, (start,))]
        while stack:
            arm, walked = stack.pop()
            for after in before[arm]:
                if after == start:
                    return (*walked, start)
                if after not in walked:
                    stack.append((after, (*walked, after)))
    return ()


@dataclass(frozen=True)
class BlockedTurn:
    """Where, with arm ``first`` going first, one arm, moving, comes closest to another resting
    at its start or end (``rests_at``): the arms (indices), the moving arm's path parameter
    ``s``, the two links and the distance (m, negative where they overlap) between them."""

    first: int
    moving: int
    resting: int
    rests_at: str
    s: float
    moving_link: str
    resting_link: str
    distance: float

    def said(self) -> str:
        """The turn in the library's words."""
        near = (f"overlaps link {self.resting_link!r} of arm {self.resting} resting at its {self.rests_at} by {-self.distance:.3g} m"
                if self.distance < 0.0 else
                f"comes within {self.distance:.3g} m of link {self.resting_link!r} of arm {self.resting} resting at its {self.rests_at}")
        return f"with arm {self.first} first, arm {self.moving}'s link {self.moving_link!r} at s = {self.s:.3g} {near}"


def _blocked_turns(cell: Cell, diagrams: dict[tuple[int, int], Diagram], a: int, b: int) -> list[BlockedTurn]:
    """For arms ``a`` < ``b`` that can take turns in neither order (in each, the arm that waits
    for the other to end first leaves the free part of their diagram on its borders, as
    ``prioritized`` checks it), the closest approach on the borders of each order: [] when
    either order is free there.

    Arm a first: a moves while b rests at its start (column s_b = 0), then b while a rests at
    its end (row s_a = 1); b first: the row s_a = 0 and the column s_b = 1."""
    diagram = diagrams[(a, b)]
    d, s = diagram.distance, diagram.s
    if any(_orders(diagram)):
        return []
    borders = {  # order: ((distances, moving, resting, rests at), ...) along the moving arm's s
        a: ((d[:, 0], a, b, "start"), (d[-1, :], b, a, "end")),
        b: ((d[0, :], b, a, "start"), (d[:, -1], a, b, "end")),
    }
    turns = []
    for first, order in borders.items():
        distance, index, moving, resting, at = min((float(line.min()), int(line.argmin()), moving, resting, at) for line, moving, resting, at in order)
        rest = np.array([0.0 if at == "start" else 1.0])
        _, k_moving, k_resting = pair_distances(arm_capsules(cell.arms[moving], s[index : index + 1]), arm_capsules(cell.arms[resting], rest))
        turns.append(BlockedTurn(
            first, moving, resting, at, float(s[index]), cell.arms[moving].link_names()[int(k_moving[0])],
            cell.arms[resting].link_names()[int(k_resting[0])], distance,
        ))
    return turns
