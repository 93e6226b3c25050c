"""The curve of a grid path, piece by piece (``toptraj.planners.generators.search.curve``): each span of the B-spline
depends on three consecutive moves of the grid path, so the pieces of curve the search needs are
the spans of every three consecutive moves the direction-augmented graph allows:

* first spans (start; e1, e2): the reflected control point before the start, then e1, e2;
* middle spans (e_a, e_b, e_c): two consecutive turns of the augmented graph;
* last spans (e_a, e_b; goal): e_b ends at a goal, the reflected point after it;
* direct spans (start; e; goal): a one-move path.

The curve up to the knot at a partial path's last-but-one grid point is then fixed whatever the
path does next. Every span is sampled on ``INTERVALS`` equal intervals of its parameter u (one
unit per span; the grid path's own s = u / L).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.generators.search.curve import span_values

#: Intervals of the phase-plane grid per span.
INTERVALS = 8
#: Piece kinds.
FIRST, MIDDLE, LAST, DIRECT = 0, 1, 2, 3


@dataclass(frozen=True)
class Pieces:
    """Every span of the augmented graph, sampled on intervals of its parameter u.

    Attributes:
        kind: ``FIRST``, ``MIDDLE``, ``LAST`` or ``DIRECT`` per piece, shape (K,).
        turn_in, turn_out: For middle spans the two turns (indices into the graph's
            transitions), for first spans the turn (``turn_out``), for last spans the turn
            (``turn_in``); -1 elsewhere. For direct spans ``edge`` is the move.
        edge: The move of a direct span, -1 elsewhere.
        corner: The grid point at the span's start knot (its second control point), shape (K,).
        control: The four control points of each span, shape (K, 4, n_dof).
        first: Index of each piece's first interval, shape (K + 1,).
        ds: Parameter length of every interval (1 / INTERVALS), shape (I,).
        q, dq, ddq: Configuration and its first and second u-derivatives at each piece's
            INTERVALS + 1 samples (its intervals' ends), shape (K, INTERVALS + 1, n_dof): held
            once, an interval's end being the next one's start (``q0`` ... ``ddq1`` give them
            per interval).
        reach_l1: A bound on the L1 joint distance from the corner point to any point of the
            span (the span lies in the convex hull of its control points), shape (K,).
    """

    kind: np.ndarray
    turn_in: np.ndarray
    turn_out: np.ndarray
    edge: np.ndarray
    corner: np.ndarray
    control: np.ndarray
    first: np.ndarray
    ds: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    reach_l1: np.ndarray

    def __len__(self) -> int:
        return len(self.kind)

    @staticmethod
    def _starts(x: np.ndarray) -> np.ndarray:
        return x[:, :-1].reshape(-1, x.shape[2])

    @staticmethod
    def _ends(x: np.ndarray) -> np.ndarray:
        return x[:, 1:].reshape(-1, x.shape[2])

    @property
    def q0(self) -> np.ndarray:
        """q at each interval's start, shape (I, n_dof) (a copy)."""
        return self._starts(self.q)

    @property
    def dq0(self) -> np.ndarray:
        """dq/du at each interval's start, shape (I, n_dof) (a copy)."""
        return self._starts(self.dq)

    @property
    def ddq0(self) -> np.ndarray:
        """d2q/du2 at each interval's start, shape (I, n_dof) (a copy)."""
        return self._starts(self.ddq)

    @property
    def q1(self) -> np.ndarray:
        """q at each interval's end, shape (I, n_dof) (a copy)."""
        return self._ends(self.q)

    @property
    def dq1(self) -> np.ndarray:
        """dq/du at each interval's end, shape (I, n_dof) (a copy)."""
        return self._ends(self.dq)

    @property
    def ddq1(self) -> np.ndarray:
        """d2q/du2 at each interval's end, shape (I, n_dof) (a copy)."""
        return self._ends(self.ddq)

    def sample(self, piece_ids: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
        """Configurations along the given spans at most ``spacing`` (joint-space norm) apart,
        ends included: q (k, n_dof) and the piece each belongs to (k,). The speed |dq/du| of a
        span is at most its largest control-point difference."""
        piece_ids = np.asarray(piece_ids, dtype=int)
        if not piece_ids.size:
            return np.empty((0, self.control.shape[2])), np.empty(0, dtype=int)
        control = self.control[piece_ids]
        steps = np.linalg.norm(np.diff(control, axis=1), axis=2).max(axis=1)
        count = int(max(1, np.ceil(steps.max() / spacing)))
        q = span_values(control, np.linspace(0.0, 1.0, count + 1))[0]
        return q.reshape(-1, q.shape[2]), np.repeat(piece_ids, count + 1)


def span_keys(
    edge_from: np.ndarray, edge_to: np.ndarray, start: int, goals: np.ndarray, turn_in: np.ndarray, turn_out: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The spans the augmented graph allows: (kind, turn_in, turn_out, edge) per span, as arrays,
    from the graph's moves and its turns (pairs of moves at grid points that are no goal)."""
    into_goal = np.isin(edge_to, goals)
    from_start = edge_from == start
    n_turns = len(turn_in)
    turns = np.arange(n_turns)
    # middle spans: turn (e_a, e_b) followed by turn (e_b, e_c)
    order = np.argsort(turn_in, kind="stable")
    bounds = np.searchsorted(turn_in[order], np.arange(len(edge_from) + 1))
    counts = bounds[turn_out + 1] - bounds[turn_out]
    before = np.repeat(turns, counts)
    offset = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    after = order[bounds[turn_out[before]] + offset]
    first = turns[from_start[turn_in]]
    last = turns[into_goal[turn_out]]
    direct = np.flatnonzero(from_start & into_goal)
    kind = np.concatenate([np.full(len(first), FIRST), np.full(len(before), MIDDLE), np.full(len(last), LAST), np.full(len(direct), DIRECT)])
    none = np.full
    return (
        kind,
        np.concatenate([none(len(first), -1), before, last, none(len(direct), -1)]),
        np.concatenate([first, after, none(len(last), -1), none(len(direct), -1)]),
        np.concatenate([none(len(first) + len(before) + len(last), -1), direct]),
    )


def build_pieces(
    points: np.ndarray, edge_from: np.ndarray, edge_to: np.ndarray, start: int, goals: np.ndarray, turn_in: np.ndarray,
    turn_out: np.ndarray,
) -> Pieces:
    """Every span of ``span_keys``, its control points and its samples."""
    kind, t_in, t_out, edge = span_keys(edge_from, edge_to, start, goals, turn_in, turn_out)
    n = points.shape[1]
    P = points
    control = np.empty((len(kind), 4, n))
    corner = np.empty(len(kind), dtype=int)
    # first: (2 S - x1, S, x1, x2) for turn (e1, e2)
    m = kind == FIRST
    e1, e2 = turn_in[t_out[m]], turn_out[t_out[m]]
    s, x1, x2 = P[edge_from[e1]], P[edge_to[e1]], P[edge_to[e2]]
    control[m] = np.stack([2 * s - x1, s, x1, x2], axis=1)
    corner[m] = edge_from[e1]
    # middle: (from e_a, to e_a, to e_b, to e_c)
    m = kind == MIDDLE
    ea, eb, ec = turn_in[t_in[m]], turn_out[t_in[m]], turn_out[t_out[m]]
    control[m] = np.stack([P[edge_from[ea]], P[edge_to[ea]], P[edge_to[eb]], P[edge_to[ec]]], axis=1)
    corner[m] = edge_to[ea]
    # last: (from e_a, to e_a, goal, 2 goal - to e_a)
    m = kind == LAST
    ea, eb = turn_in[t_in[m]], turn_out[t_in[m]]
    a, b, g = P[edge_from[ea]], P[edge_to[ea]], P[edge_to[eb]]
    control[m] = np.stack([a, b, g, 2 * g - b], axis=1)
    corner[m] = edge_to[ea]
    # direct: (2 S - G, S, G, 2 G - S)
    m = kind == DIRECT
    s, g = P[edge_from[edge[m]]], P[edge_to[edge[m]]]
    control[m] = np.stack([2 * s - g, s, g, 2 * g - s], axis=1)
    corner[m] = edge_from[edge[m]]
    t = np.linspace(0.0, 1.0, INTERVALS + 1)
    q, dq, ddq = span_values(control, t)  # (K, INTERVALS + 1, n)
    reach_l1 = np.abs(control - control[:, 1:2]).sum(axis=2).max(axis=1)
    return Pieces(
        kind=kind, turn_in=t_in, turn_out=t_out, edge=edge, corner=corner, control=control,
        first=np.arange(len(kind) + 1) * INTERVALS, ds=np.full(len(kind) * INTERVALS, 1.0 / INTERVALS),
        q=np.ascontiguousarray(q), dq=np.ascontiguousarray(dq), ddq=np.ascontiguousarray(ddq), reach_l1=reach_l1,
    )
