"""The branch and bound's subsets and queue as arrays (``toptraj.planners.generators.search.search_kernels``):
the problem's moves laid out for the compiled loop, the node table and heap grown by doubling up
to ``MAX_NODE_BYTES``, and the counters read back into the search's statistics."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from toptraj.planners.generators.search import search_kernels as kernels
from toptraj.planners.generators.search.outcome import SearchStatistics
from toptraj.planners.generators.search.problem import SearchProblem

#: Relative slack of a bound over t_u before it discards (float rounding between the bound's
#: and the phase-plane method's sums of the same intervals).
SLACK = 1e-9
#: Pops of one compiled chunk: the deadline is checked and progress reported between chunks
#: (about a millisecond of work each).
CHUNK_POPS = 1_024
#: Most bytes of the node table and heap together (112 bytes a subset: about 1.2 million
#: subsets): beyond, the search stops as at ``max_expansions``. The isolated worker's memory
#: cap allows 1 GiB above the search's estimate (``toptraj.planners.generators.search.memory``).
MAX_NODE_BYTES = 2**27
#: Bytes per row: five 8-byte ints and six 8-byte floats of the node, and a heap entry.
ROW_BYTES = 11 * 8 + 3 * 8
#: Rows allocated at first.
FIRST_ROWS = 4_096
# the compiled kernels, called with the table's arrays unpacked
_child: Callable[..., Any] = kernels.child
_run_chunk: Callable[..., Any] = kernels.run_chunk
_settle_t4: Callable[..., Any] = kernels.settle_t4


class NodeTable:
    """The node table (row 0 the root), the heap and the counters of one branch and bound over
    ``problem``, with a first upper bound ``t_u`` (s)."""

    def __init__(self, problem: SearchProblem, t_u: float):
        successors = problem.successors
        counts = np.array([len(s) for s in successors], dtype=np.int64)
        flat = [move for moves in successors for move in moves]
        moves = np.array(flat, dtype=np.int64).reshape(-1, 3)
        self.moves = (
            np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
            np.ascontiguousarray(moves[:, 0]),
            np.ascontiguousarray(moves[:, 1]),
            np.ascontiguousarray(moves[:, 2]),
            np.asarray(problem.turn_out, dtype=np.int64),
            np.asarray(problem.graph.edge_to, dtype=np.int64),
            int(problem.graph.start),
        )
        b = problem.bounds
        self.bounds = (
            b.t1, b.t2, problem.h1, problem.h2, np.asarray(problem.pieces.first, dtype=np.int64), b.ds,
            np.ascontiguousarray(b.p), np.ascontiguousarray(b.q), np.ascontiguousarray(b.r), b.cap_start, b.cap_end,
        )
        # one expansion adds at most two rows per move (a completed path is two nodes)
        widest = int(counts.max(initial=0))
        self.room = 2 * max(widest, len(problem.start_moves)) + 2
        rows = max(FIRST_ROWS, 4 * self.room)
        self.ints = np.zeros((rows, 5), dtype=np.int64)
        self.floats = np.zeros((rows, 6))
        self.key, self.order, self.node = np.zeros(rows), np.zeros(rows, dtype=np.int64), np.zeros(rows, dtype=np.int64)
        self.counters = np.zeros(10, dtype=np.int64)
        self.upper = np.array([t_u], dtype=float)
        self.out_key = np.zeros(1)
        self.ints[0] = (-1, -1, -1, -1, 0)
        self.floats[0] = (0.0, 0.0, 0.0, 0.0, np.nan, np.nan)
        self.counters[kernels.NODES] = 1

    def _queue(self):
        return self.ints, self.floats, self.key, self.order, self.node, self.counters, self.upper, SLACK

    def child(self, parent: int, state: int, edge: int, piece: int, ending: int) -> None:
        """A first move from the root (``kernels.child`` with no parent key)."""
        _child(*self._queue(), parent, state, edge, piece, ending, 0.0, *self.bounds)

    def chunk(self, max_expansions: int) -> tuple[int, int]:
        """``kernels.run_chunk``: what stopped it and the node concerned."""
        status, index = _run_chunk(
            *self._queue(), CHUNK_POPS, max_expansions, self.room, self.out_key, *self.moves, *self.bounds
        )
        return int(status), int(index)

    def settle(self, index: int, t4: float, upper_margin: float) -> None:
        """Node ``index``, popped at ``out_key``, timed at ``t4`` (``kernels.settle_t4``)."""
        _settle_t4(*self._queue(), upper_margin, index, float(self.out_key[0]), t4)

    def grow(self) -> bool:
        """Twice the rows (node table and heap); False when that passes ``MAX_NODE_BYTES``."""
        rows = 2 * len(self.ints)
        if rows * ROW_BYTES > MAX_NODE_BYTES:
            return False

        def larger(array: np.ndarray) -> np.ndarray:
            out = np.zeros((rows, *array.shape[1:]), dtype=array.dtype)
            out[: len(array)] = array
            return out

        self.ints, self.floats = larger(self.ints), larger(self.floats)
        self.key, self.order, self.node = larger(self.key), larger(self.order), larger(self.node)
        return True

    def edges(self, index: int) -> list[int]:
        """The moves of the path ending at node ``index``, from the start."""
        return self._along(index, kernels.EDGE)

    def pieces(self, index: int) -> list[int]:
        """The spans of the path ending at node ``index``, from the start."""
        return self._along(index, kernels.PIECE)

    def _along(self, index: int, column: int) -> list[int]:
        """The values >= 0 of ``column`` on the chain of parents of node ``index``, from the start."""
        out = []
        while index >= 0:
            if self.ints[index, column] >= 0:
                out.append(int(self.ints[index, column]))
            index = int(self.ints[index, kernels.PARENT])
        return out[::-1]

    def count_into(self, stats: SearchStatistics) -> None:
        """The counters added to ``stats``."""
        c = self.counters
        stats.expanded += int(c[kernels.EXPANDED])
        stats.generated += int(c[kernels.GENERATED])
        for name, column in (("t1", kernels.PRUNED_T1), ("t2", kernels.PRUNED_T2), ("t3", kernels.PRUNED_T3),
                             ("t4", kernels.PRUNED_T4), ("t_u", kernels.PRUNED_TU)):
            stats.pruned[name] += int(c[column])
