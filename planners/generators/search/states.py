"""The branch and bound's states and moves toward the goal points, and each state's cost to go
(``toptraj.planners.generators.search.problem``), built with array operations from the spans.

A state is a turn of the direction-augmented graph (two moves, the span between them not yet
fixed), or one move from the start. A usable first or middle span k, between the turns
``before`` and ``after``, is the move ``before -> after``; when the move of ``after`` ends at a
goal point, the move also names the usable last span into it (``ending``; no move where that
span is not usable). The cost to go h2 of a state is the least t2 (Jeong & Lee eq. 2.7) over
the graph's spans from it to one of ``graph.goals``: Dijkstra from the goals over the reversed
moves. Only the last spans into ``graph.goals`` end a completion, so a state from which none
of them is reachable has ``inf``: its subsets are discarded by t1 at once.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.search.bounds import PieceBounds
from toptraj.planners.generators.search.graph import SearchGraph
from toptraj.planners.generators.search.pieces import DIRECT, FIRST, LAST, MIDDLE, Pieces


class States(NamedTuple):
    """The states and moves toward some goal points (``SearchProblem`` names them).

    Attributes:
        successors: Per state, its moves on: (after, span, ending).
        start_moves: Per move from the start: (edge, state or -1 into a goal, direct span or -1).
        state_point: The grid point each state's last move ends at, shape (S,).
        h2: The cost to go of each state (s), shape (S,).
        cut: The point where each state's fixed curve ends, shape (S, n_dof).
    """

    successors: list[list[tuple[int, int, int]]]
    start_moves: list[tuple[int, int, int]]
    state_point: np.ndarray
    h2: np.ndarray
    cut: np.ndarray


def cost_to_go(n_states: int, source: np.ndarray, target: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Least cost (n_states,) from each state to a goal over arcs (source, target, weight), each
    (A,), target -1 the goal: Dijkstra from the goal over the reversed arcs."""
    if not len(source):
        return np.full(n_states, np.inf)
    from scipy.sparse import csr_matrix  # here: scipy.sparse is imported by the searches only
    from scipy.sparse.csgraph import dijkstra

    target = np.where(target < 0, n_states, target)
    finite = np.isfinite(weight)
    reversed_arcs = csr_matrix(
        (weight[finite] + 1e-300, (target[finite], source[finite])), shape=(n_states + 1, n_states + 1)
    )  # 1e-300: sparse matrices drop zero weights
    return dijkstra(reversed_arcs, directed=True, indices=n_states)[:n_states]


def _moves(graph: SearchGraph, turn_in, turn_out, pieces: Pieces, usable, goal: np.ndarray, last: np.ndarray):
    """The moves (before, after, span, ending), each (M,), in the order of the spans; states
    after the turns, the start's moves numbered from ``len(turn_in)``."""
    n_turns = len(turn_in)
    start_state = np.full(len(graph.edge_from), -1)
    starts = np.flatnonzero(graph.edge_from == graph.start)
    start_state[starts] = n_turns + np.arange(len(starts))
    span = np.flatnonzero(usable & ((pieces.kind == FIRST) | (pieces.kind == MIDDLE)))
    after = pieces.turn_out[span].astype(np.int64)
    before = np.where(pieces.kind[span] == MIDDLE, pieces.turn_in[span], start_state[turn_in[after]])
    into_goal = goal[graph.edge_to[turn_out[after]]]
    ending = np.where(into_goal, last[after], -1)
    keep = ~(into_goal & (ending < 0))  # the last span into the goal is not usable
    return before[keep].astype(np.int64), after[keep], span[keep].astype(np.int64), ending[keep].astype(np.int64)


def _grouped(n_states: int, before: np.ndarray, after: np.ndarray, span: np.ndarray, ending: np.ndarray) -> list[list[tuple[int, int, int]]]:
    """Per state, its moves (after, span, ending) in the order of the spans."""
    order = np.argsort(before, kind="stable")
    rows = list(zip(after[order].tolist(), span[order].tolist(), ending[order].tolist()))
    bounds = np.concatenate([[0], np.cumsum(np.bincount(before, minlength=n_states))]).tolist()
    return [rows[bounds[s] : bounds[s + 1]] for s in range(n_states)]


def search_states(
    graph: SearchGraph, turn_in: np.ndarray, turn_out: np.ndarray, pieces: Pieces, bounds: PieceBounds, usable: np.ndarray,
    deadline: Deadline = NO_DEADLINE,
) -> States:
    """The search's states and moves toward ``graph.goals`` (module docstring), ``deadline``
    checked before and after."""
    deadline.check()
    n_turns = len(turn_in)
    starts = np.flatnonzero(graph.edge_from == graph.start)
    goal = np.zeros(len(graph.points), dtype=bool)
    goal[graph.goals] = True
    n_states = n_turns + len(starts)
    state_point = np.concatenate([graph.edge_to[turn_out], graph.edge_to[starts]])
    last = np.full(n_turns, -1)
    keep = usable & (pieces.kind == LAST)
    last[pieces.turn_in[keep]] = np.flatnonzero(keep)
    before, after, span, ending = _moves(graph, turn_in, turn_out, pieces, usable, goal, last)
    successors = _grouped(n_states, before, after, span, ending)
    # the last spans into these goals only: the others end where no grid path to them goes on
    into = np.flatnonzero((last >= 0) & goal[graph.edge_to[turn_out]])
    source = np.concatenate([before, into])
    target = np.concatenate([after, np.full(len(into), -1)])
    weight = np.concatenate([bounds.t2[span], bounds.t2[last[into]]]).astype(float)
    h2 = cost_to_go(n_states, source, target, weight)
    deadline.check()
    direct = np.full(len(graph.edge_from), -1)
    straight = np.flatnonzero(usable & (pieces.kind == DIRECT))
    direct[pieces.edge[straight]] = straight
    start_moves = [
        (int(e), -1 if goal[graph.edge_to[e]] else n_turns + k, int(direct[e])) for k, e in enumerate(starts)
    ]
    P = graph.points
    cut = np.concatenate([
        (P[graph.edge_from[turn_in]] + 4.0 * P[graph.edge_to[turn_in]] + P[graph.edge_to[turn_out]]) / 6.0,
        P[np.full(len(starts), graph.start)],
    ])
    return States(successors, start_moves, state_point, h2, cut)
