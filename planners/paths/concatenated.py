"""Paths joined end to end, the motion stopping where they meet (a corner in joint space)."""

from __future__ import annotations

import numpy as np

from toptraj.planners.paths.base import GeometricPath, PathPoints


class ConcatenatedPath(GeometricPath):
    """Pieces laid one after the other on s in [0, 1], piece k on [b_k, b_k+1] with the break
    points ``b`` proportional to ``weights``; each piece runs over its own s in [0, 1], so the
    s-derivatives scale by 1 / (b_k+1 - b_k). Every junction is a kink.

    Args:
        pieces: Paths over s in [0, 1] with equal dof, each ending where the next begins.
        weights: Positive relative lengths of the pieces in s.
    """

    def __init__(self, pieces: list[GeometricPath], weights: np.ndarray):
        self.pieces = list(pieces)
        self.dof = pieces[0].dof
        weights = np.asarray(weights, dtype=float)
        self.knots = np.concatenate(([0.0], np.cumsum(weights) / weights.sum()))
        self.knots[-1] = 1.0
        self.kinks = self.knots[1:-1].copy() if len(pieces) > 1 else np.empty(0)

    def _locate(self, s, side):
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        piece = np.searchsorted(self.knots, s, side="left" if side == "left" else "right") - 1
        piece = np.clip(piece, 0, len(self.pieces) - 1)
        width = np.diff(self.knots)[piece]
        return piece, (s - self.knots[piece]) / width, width

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        piece, local, width = self._locate(s, side)
        q, dq, ddq = (np.empty((len(local), self.dof)) for _ in range(3))
        for k, path in enumerate(self.pieces):
            mine = piece == k
            if np.any(mine):
                points = path.evaluate(np.clip(local[mine], 0.0, 1.0))
                q[mine] = points.q
                dq[mine] = points.dq / width[mine][:, None]
                ddq[mine] = points.ddq / (width[mine] ** 2)[:, None]
        return PathPoints(q, dq, ddq)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        piece, local, width = self._locate(s, side)
        out = np.empty((len(local), self.dof))
        for k, path in enumerate(self.pieces):
            mine = piece == k
            if np.any(mine):
                out[mine] = path.third_derivative(np.clip(local[mine], 0.0, 1.0), side) / (width[mine] ** 3)[:, None]
        return out
