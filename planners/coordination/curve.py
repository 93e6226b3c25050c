"""The shortest monotone coordination curve through the free part of the diagram (O'Donnell &
Lozano-Pérez 1989, §4), and its smoothing into a curve both arms can follow at speed.

The grid's nodes form a graph whose edges step one node in s1, in s2, or in both; monotone, so
Dijkstra's algorithm reduces to one pass in the order of the nodes (a shortest path in a
directed acyclic graph). An edge costs the time the arms need for it: dt1[i] for a step of
s1 alone, dt2[j] for s2 alone, the larger of the two for both, each arm's time over that step
of its own time-optimal motion.

The staircase of nodes found is smoothed into a cubic B-spline that takes the nodes as control
points (clamped at (0, 0) and (1, 1)): with non-decreasing control points each coordinate is
non-decreasing (a B-spline's derivative is a B-spline of the differences of its control points,
de Boor, *A Practical Guide to Splines*, ch. IX), it is C2, and it stays within the convex hull
of four successive nodes.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.coordination.diagram import Diagram
from toptraj.planners.errors import InfeasiblePath

#: Moves of the graph: (di, dj).
_MOVES = ((1, 0), (0, 1), (1, 1))


def _costs(blocked: np.ndarray, dt1: np.ndarray, dt2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least time to reach each node (M + 1, M + 1) from (0, 0), and the move (index in
    ``_MOVES``, -1 at the start or where unreachable) that reaches it."""
    n1, n2 = blocked.shape
    cost = np.full((n1, n2), np.inf)
    move = np.full((n1, n2), -1, dtype=int)
    cost[0, 0] = 0.0
    for i in range(n1):
        if i > 0:
            straight = cost[i - 1] + dt1[i - 1]
            diagonal = np.full(n2, np.inf)
            diagonal[1:] = cost[i - 1, :-1] + np.maximum(dt1[i - 1], dt2)
            row = np.minimum(straight, diagonal)
            move[i] = np.where(diagonal < straight, 2, 0)
            cost[i] = np.where(blocked[i], np.inf, row)
        for j in range(1, n2):  # steps of s2 alone, along the row
            if not blocked[i, j] and cost[i, j - 1] + dt2[j - 1] < cost[i, j]:
                cost[i, j] = cost[i, j - 1] + dt2[j - 1]
                move[i, j] = 1
    move[~np.isfinite(cost)] = -1
    return cost, move


def shortest_curve(diagram: Diagram, dt1: np.ndarray, dt2: np.ndarray) -> np.ndarray:
    """The nodes (n, 2) of (s1, s2) of the quickest monotone curve from (0, 0) to (1, 1)
    through free nodes, the cost of a step being the arms' time over it (``dt1``, ``dt2``
    (M,), s).

    Raises:
        InfeasiblePath: no monotone curve avoids the collision region.
    """
    cost, move = _costs(diagram.blocked, dt1, dt2)
    last = len(diagram.s) - 1
    if not np.isfinite(cost[last, last]):
        reached = np.argwhere(np.isfinite(cost))
        far = reached[np.argmax(reached.sum(axis=1))]
        raise InfeasiblePath(
            "the arms cannot pass each other along these paths: every coordination of the two motions brings them closer "
            f"than the clearance; the farthest reachable is s1 = {diagram.s[far[0]]:.3g}, s2 = {diagram.s[far[1]]:.3g}: "
            "move a base apart, change a path or lower clearance",
            s=float(diagram.s[far[0]]),
        )
    nodes = [(last, last)]
    while nodes[-1] != (0, 0):
        i, j = nodes[-1]
        di, dj = _MOVES[move[i, j]]
        nodes.append((i - di, j - dj))
    return diagram.s[np.array(nodes[::-1])]


def _segment_free(diagram: Diagram, start: np.ndarray, end: np.ndarray) -> bool:
    """Whether the straight segment from ``start`` to ``end`` ((s1, s2) each) stays in cells
    with four free corners, checked at a quarter of a cell."""
    count = int(np.ceil(np.abs(end - start).max() * (len(diagram.s) - 1) * 4)) + 1
    w = np.linspace(0.0, 1.0, count + 1)[:, None]
    points = start + w * (end - start)
    return bool(diagram.free_at(points[:, 0], points[:, 1]).all())


def widened(diagram: Diagram, cells: int) -> Diagram:
    """``diagram`` with its collision region grown by ``cells`` nodes (8-neighbourhood), the
    two ends left free."""
    from scipy.ndimage import binary_dilation  # here: scipy's modules load where a cell is planned

    blocked = binary_dilation(diagram.blocked, np.ones((3, 3), dtype=bool), iterations=cells)
    blocked[0, 0] = blocked[-1, -1] = False
    return Diagram(diagram.s, diagram.distance, blocked, diagram.step1, diagram.step2)


def shortcut(diagram: Diagram, nodes: np.ndarray, spacing: float | None = None) -> np.ndarray:
    """The staircase ``nodes`` (n, 2) straightened: from each kept node, on along the nodes as
    long as a straight segment reaches them through ``diagram`` widened by one node; the polyline
    then resampled every ``spacing`` (default: one grid step) at most, so that the B-spline of
    its points (``SmoothCurve``) strays less than a grid step from it, rounding its corners.
    Straight segments between monotone nodes stay monotone. With ``nodes`` found in the
    diagram widened by two nodes, the smoothed curve stays in cells of ``diagram`` with four
    free corners."""
    spacing = float(diagram.s[1] - diagram.s[0]) if spacing is None else spacing
    diagram = widened(diagram, 1)
    kept, k = [0], 0
    while k < len(nodes) - 1:
        m = k + 1
        while m < len(nodes) - 1 and _segment_free(diagram, nodes[k], nodes[m + 1]):
            m += 1
        kept.append(m)
        k = m
    points = [nodes[0]]
    for a, b in zip(kept[:-1], kept[1:]):
        pieces = max(1, int(np.ceil(np.abs(nodes[b] - nodes[a]).max() / spacing)))
        points += [nodes[a] + (nodes[b] - nodes[a]) * w for w in np.linspace(0.0, 1.0, pieces + 1)[1:]]
    return np.array(points)


def resampled(points: np.ndarray, spacing: float) -> np.ndarray:
    """Points every ``spacing`` or less of arc length along the polyline ``points`` (n, 2), its
    ends kept and its other vertices dropped: control points of a smoother ``SmoothCurve``
    that rounds the polyline's corners more widely (monotone: points of a monotone polyline in
    order)."""
    length = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    at = np.linspace(0.0, length[-1], int(np.ceil(length[-1] / spacing)) + 1)
    return np.column_stack([np.interp(at, length, points[:, 0]), np.interp(at, length, points[:, 1])])


class SmoothCurve:
    """A C2 monotone coordination curve sigma -> (s1, s2), sigma in [0, 1], the clamped cubic
    B-spline whose control points are ``nodes`` (n, 2)."""

    def __init__(self, nodes: np.ndarray):
        nodes = np.asarray(nodes, dtype=float)
        if len(nodes) < 4:  # a cubic needs four control points
            nodes = np.array([nodes[0] + (nodes[-1] - nodes[0]) * w for w in np.linspace(0.0, 1.0, 4)])
        interior = np.linspace(0.0, 1.0, len(nodes) - 2)[1:-1]
        knots = np.r_[np.zeros(4), interior, np.ones(4)]
        self.nodes = nodes
        from scipy.interpolate import BSpline  # here: scipy's modules load where a cell is planned

        self._spline = BSpline(knots, nodes, 3, extrapolate=False)

    def evaluate(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s, ds/dsigma, d2s/dsigma2) at ``sigma`` (n,), each (n, 2); s clipped to [0, 1]."""
        sigma = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
        s = np.clip(self._spline(sigma), 0.0, 1.0)
        ds = np.maximum(self._spline.derivative(1)(sigma), 0.0)
        dds = self._spline.derivative(2)(sigma)
        return s, ds, dds
