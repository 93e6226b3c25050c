"""A stretch of a path between two of its corners, re-parameterized over its own s in [0, 1].

At a corner (kink) the motion stops, so the stretches between corners are independent
rest-to-rest problems: each is timed on its own, in its own parameter, whatever its length
relative to the rest of the path (``toptraj.planners.timing.segmented``).
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.paths.base import GeometricPath, PathPoints


class Stretch(GeometricPath):
    """q(a + w sigma) for sigma in [0, 1], w = b - a, of a ``parent`` path without kinks inside
    (a, b). Derivatives in sigma: dq/dsigma = w q'(s), d2q/dsigma2 = w^2 q''(s). The end sigma = 1
    is evaluated from the inside (the parent's left-hand side at b), sigma = 0 from the right.

    Args:
        parent: The whole path.
        start, end: The stretch's ends a < b in the parent's s.
    """

    def __init__(self, parent: GeometricPath, start: float, end: float):
        self.parent = parent
        self.start, self.end = float(start), float(end)
        self.width = self.end - self.start
        self.dof = parent.dof
        inner = parent.knots[(parent.knots > start) & (parent.knots < end)]
        self.knots = np.concatenate(([0.0], (inner - start) / self.width, [1.0]))
        self._parent_knots = np.concatenate(([self.start], inner, [self.end]))
        self.kinks = np.empty(0)
        breaks = np.asarray(parent.breaks, dtype=float)
        self.breaks = (breaks[(breaks > start) & (breaks < end)] - start) / self.width

    def to_parent(self, sigma: np.ndarray) -> np.ndarray:
        """The parent's s at ``sigma``: each of this stretch's knots exactly at the parent's
        knot (so that one-sided values at the parent's breaks are taken on the right side)."""
        sigma = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
        s = self.start + self.width * sigma
        index = np.clip(np.searchsorted(self.knots, sigma), 0, len(self.knots) - 1)
        return np.where(self.knots[index] == sigma, self._parent_knots[index], s)

    def _on_parent(self, sigma, evaluate, side="right"):
        """``evaluate(s, side)`` (a tuple of arrays) at the parent's s, the end from its left,
        the start from its right, the points in between from ``side`` (which matters at the
        parent's breaks)."""
        s = self.to_parent(np.atleast_1d(sigma))
        values = tuple(np.array(value) for value in evaluate(s, "right"))
        inside = (s > self.start) & (s < self.end)
        if side == "left" and inside.any():
            for value, left in zip(values, evaluate(s[inside], "left")):
                value[inside] = left
        at_end = s >= self.end
        if at_end.any():
            for value, end in zip(values, evaluate(s[at_end], "left")):
                value[at_end] = end
        return values

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        q, dq, ddq = self._on_parent(s, lambda s_, side_: tuple(self.parent.evaluate(s_, side_)), side)
        return PathPoints(q, dq * self.width, ddq * self.width**2)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        (third,) = self._on_parent(s, lambda s_, side_: (self.parent.third_derivative(s_, side_),), side)
        return third * self.width**3


def stretches(path: GeometricPath) -> list[GeometricPath]:
    """The path itself when it has no corner, else its stretches between corners."""
    kinks = np.asarray(path.kinks, dtype=float)
    if kinks.size == 0:
        return [path]
    edges = np.concatenate(([0.0], kinks, [1.0]))
    return [Stretch(path, a, b) for a, b in zip(edges[:-1], edges[1:])]
