"""The geometric path q(s), s in [0, 1]: geometry only, never time (lecture seed: a *path* is
geometry, a *trajectory* is a path plus a timing s(t))."""

from __future__ import annotations

import abc
from typing import NamedTuple

import numpy as np

#: Distance (joint units) by which a path may pass beyond a joint's range: rounding.
RANGE_SLACK = 1e-9


class PathPoints(NamedTuple):
    """A path and its s-derivatives at n_samples values of s, each of shape (n_samples, n_dof).

    Units: q in the joint units (rad, m); dq = dq/ds and ddq = d2q/ds2 in those units (s is
    dimensionless).
    """

    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray


class GeometricPath(abc.ABC):
    """A joint path on s in [0, 1], C2 except at its ``kinks``.

    Attributes:
        dof: Number of joints.
        knots: Increasing s values (including 0 and 1) that any grid over the path should hold:
            waypoints and the breaks of the piecewise definition.
        kinks: Interior s values where dq/ds jumps (corners): the motion must stop there, and
            the two sides have different derivatives.
        breaks: Interior s values where dq/ds is continuous but d2q/ds2 jumps (a straight
            segment meeting a circular blend): the motion goes on, but the limits seen from the
            two sides differ. ``evaluate`` honours ``side`` there too.
    """

    dof: int
    knots: np.ndarray
    kinks: np.ndarray
    breaks: np.ndarray = np.empty(0)

    @abc.abstractmethod
    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        """q, dq/ds and d2q/ds2 at ``s`` (shape (n_samples,)); at a kink or a break, the one-sided
        derivatives of ``side`` ("left" or "right")."""

    @abc.abstractmethod
    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        """d3q/ds3 at ``s``, shape (n_samples, n_dof) (for jerk)."""

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """q(s), shape (n_samples, n_dof)."""
        return self.evaluate(np.atleast_1d(np.asarray(s, dtype=float))).q

    def outside_range(self, lower: np.ndarray, upper: np.ndarray, samples: int) -> tuple[float, int, float] | None:
        """(s, joint, q) of a point where the path lies beyond [``lower``, ``upper``] (n_dof,
        each) by more than ``RANGE_SLACK``, or ``None``: here the first of ``samples`` evenly
        spaced values of s that does; a path of polynomial pieces finds its farthest point
        exactly."""
        dense = np.linspace(0.0, 1.0, samples)
        q = self(dense)
        outside = (q < lower - RANGE_SLACK) | (q > upper + RANGE_SLACK)
        if not outside.any():
            return None
        row, joint = np.argwhere(outside)[0]
        return float(dense[row]), int(joint), float(q[row, joint])
