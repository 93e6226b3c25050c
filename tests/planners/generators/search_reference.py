"""The branch and bound's loop as it was in pure Python (objects and ``heapq``), kept as the
reference the compiled loop (``toptraj.planners.generators.search.search_kernels``) must agree with:
same subsets expanded in the same order, same grid paths found, same counts."""

from __future__ import annotations

import heapq

import numpy as np

from toptraj.planners.generators.search.bounds import forward_time
from toptraj.planners.generators.search.branch_and_bound import _Node, _Search
from toptraj.planners.generators.search.graph import DEFAULT_OPTIONS
from toptraj.planners.generators.search.outcome import GridPath

SLACK = 1e-9


class ReferenceSearch(_Search):
    """``_Search`` with the pure-Python loop."""

    def _above(self, value: float) -> bool:
        return not value <= self.t_u * (1.0 + SLACK)

    def child(self, parent: _Node, state: int, edge: int, piece: int, ending: int, parent_key: float) -> None:
        problem, b = self.problem, self.problem.bounds
        self.stats.generated += 1
        point = int(problem.graph.edge_to[edge])
        visited = parent.visited | (1 << point)
        complete = ending >= 0
        g1 = parent.g1 + (b.t1[piece] if piece >= 0 else 0.0)
        g2 = parent.g2 + (b.t2[piece] if piece >= 0 else 0.0)
        if complete:
            f1, f2 = g1 + b.t1[ending], g2 + b.t2[ending]
        else:
            f1, f2 = g1 + problem.h1[state], g2 + problem.h2[state]
        f1 = max(f1, parent_key)
        if self._above(f1):
            self.stats.pruned["t1"] += 1
            return
        f2 = max(f2, f1)
        if self._above(f2):
            self.stats.pruned["t2"] += 1
            return
        g3, x = parent.g3, parent.x
        if piece >= 0:
            first = problem.pieces.first
            span, x = forward_time(first[piece], first[piece + 1], b.ds, b.q, b.r, b.cap_start, b.cap_end, x)
            g3 += span
        node = _Node(state, edge, g1, g2, g3, x, visited, parent, piece)
        if complete:
            node = _Node(state, -1, f1, f2, g3, x, visited, node, ending, complete=True)
            node.t3 = self.t3_of(node)
            f3 = max(f2, node.t3)
        else:
            f3 = max(f2, g3 + problem.h2[state])
        if self._above(f3):
            self.stats.pruned["t3"] += 1
            return
        self.count += 1
        heapq.heappush(self.heap, (f3, self.count, node))

    def run(self) -> None:
        self.heap: list = []
        self.count = 0
        self.dive()
        root = self.root()
        for state, edge, piece, ending in self.starts():
            self.child(root, state, edge, piece, ending, 0.0)
        while self.heap:
            key, _, node = heapq.heappop(self.heap)
            if self._above(key):
                self.stats.pruned["t_u"] += 1 + len(self.heap)
                self.heap.clear()
                break
            if node.complete:
                if node.t4 is None:
                    node.t4 = self.t4_of(self.points(node))
                    if self._above(node.t4):
                        self.stats.pruned["t4"] += 1
                        continue
                    self._lower_t_u(node.t4)
                    self.count += 1
                    heapq.heappush(self.heap, (max(key, node.t4), self.count, node))
                    continue
                self.found.append(GridPath(self.points(node), float(node.t4), (float(node.g1), float(node.g2), float(node.t3))))
                continue
            if self.stats.expanded >= self.options.max_expansions:
                self.stats.complete = False
                break
            self.stats.expanded += 1
            turn_out, edge_to = self.problem.turn_out, self.problem.graph.edge_to
            for state, piece, ending in self.problem.successors[node.state]:
                edge = int(turn_out[state])
                if not node.visited >> int(edge_to[edge]) & 1:
                    self.child(node, state, edge, piece, ending, key)
        self.stats.upper_bound = self.t_u


def reference_search(problem, options=DEFAULT_OPTIONS, cap: float = np.inf) -> ReferenceSearch:
    """The pure-Python branch and bound of ``problem`` run to its end."""
    search = ReferenceSearch(problem, options, _no_deadline(), cap)
    search.run()
    return search


def _no_deadline():
    from toptraj.planners.execution.deadline import NO_DEADLINE

    return NO_DEADLINE
