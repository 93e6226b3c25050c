"""``JerkTimeScaling``: a time scaling s(t) with continuous path acceleration, for the
jerk-limited timing (``toptraj.planners.timing.jerk.method``).

On the grid s_0 < ... < s_N it holds x_i = sd_i^2 and u_i = sdd_i. Within an interval of width
h_i the path acceleration is linear in s, u(s) = u_i + w_i (s - s_i) with w_i = du/ds =
(u_i+1 - u_i) / h_i, so x = sd^2 (dx/ds = 2u) is quadratic,

    x(s) = x_i + 2 u_i (s - s_i) + w_i (s - s_i)^2,   x_i+1 = x_i + (u_i + u_i+1) h_i,

and the path jerk is sddd = du/dt = w_i sd. The time spent in an interval is the integral of
ds / sd, taken by Gauss-Legendre quadrature after the substitution s - s_i = h tau^2 from the
end where sd is smaller (which keeps the integrand smooth where x nears zero).

Starting from rest (x_0 = 0, u_0 = 0) the path speed of such an interval would never leave zero
(x = w s^2 gives an exponential in time), so an interval that starts or ends at rest holds the
motion of constant path jerk sigma instead: s = sigma t^3 / 6, sd = sigma t^2 / 2, sdd = sigma t,
along which u = 2 x / (3 s) and du/ds = 2 / t^2 = 2 x / (9 s^2) (mirrored at an end at rest).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from toptraj.planners.timing.base import DenseStates, TimeScaling

#: Gauss-Legendre nodes and weights on [0, 1] for the time of an interval.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(12)
_NODES, _WEIGHTS = 0.5 * (_NODES + 1.0), 0.5 * _WEIGHTS
#: The same rule on the panels [0, 2^-24], [2^-24, 2^-23], ..., [1/2, 1] of tau, for an interval
#: whose x at its two ends differ more than ``STEEP`` fold: leaving near rest, x grows from
#: x_small to x_large and the integrand turns at tau ~ sqrt(x_small / x_large), which one panel
#: of 12 nodes misses (0.055 % of an interval's time where x grew 44,000 fold; the samples'
#: positions then lag their speeds, a jump at the interval's end).
_EDGES = np.concatenate(([0.0], 2.0 ** -np.arange(24.0, -1.0, -1.0)))
_FINE_NODES = (_EDGES[:-1, None] + np.diff(_EDGES)[:, None] * _NODES[None, :]).ravel()
_FINE_WEIGHTS = (np.diff(_EDGES)[:, None] * _WEIGHTS[None, :]).ravel()
STEEP = 100.0


def _steep(x_a: np.ndarray, x_b: np.ndarray) -> np.ndarray:
    """Where x at an interval's two ends differ more than ``STEEP`` fold."""
    small, large = np.minimum(x_a, x_b), np.maximum(x_a, x_b)
    return large > STEEP * small


class _Grid(NamedTuple):
    """Per-interval arrays of a ``JerkTimeScaling``: widths h (K,), x = sd^2 at the points
    (K + 1,), du/ds w (K,), and the path jerk of the intervals at rest (0 where none)."""

    h: np.ndarray
    x: np.ndarray
    w: np.ndarray
    sigma_start: float
    sigma_end: float


def _quadrature(offset, x0, u0, w, from_start, nodes, weights) -> np.ndarray:
    """The time (s) to cover ``offset`` from an interval's start where x = x0 + 2 u0 s + w s^2
    (arrays of one shape): the integral of ds / sqrt(x) with s = offset tau^2 from the end where
    x is smaller (``from_start``: the start), by the rule ``nodes``, ``weights`` on [0, 1]."""
    at = offset[..., None] * np.where(from_start[..., None], nodes**2, 1.0 - nodes**2)
    inside = np.maximum(x0[..., None] + 2.0 * u0[..., None] * at + w[..., None] * at**2, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return offset * (weights * 2.0 * nodes / np.sqrt(inside)).sum(axis=-1)


def interval_times(s: np.ndarray, x: np.ndarray, u: np.ndarray, rest_start: bool, rest_end: bool) -> np.ndarray:
    """Time spent in each interval by each of several motions on one grid (module docstring):
    ``s`` (K + 1,), x = sd^2 and u = sdd at its points, (M, K + 1) each; returns (M, K) in s.
    The quadrature of ``JerkTimeScaling._times_to`` over whole intervals, for M motions at once
    (the line search of ``toptraj.planners.timing.jerk.method`` times eight)."""
    h = np.diff(s)
    w = np.diff(u, axis=1) / h
    sigma_start = (2.0 / 9.0) * x[:, 1] ** 1.5 / h[0] ** 2
    sigma_end = (2.0 / 9.0) * x[:, -2] ** 1.5 / h[-1] ** 2
    if rest_start:
        w[:, 0] = 2.0 * x[:, 1] / (9.0 * h[0] ** 2)
    if rest_end:
        w[:, -1] = 2.0 * x[:, -2] / (9.0 * h[-1] ** 2)
    x0, u0 = x[:, :-1], u[:, :-1]
    x_end = np.maximum(x0 + 2.0 * u0 * h + w * h**2, 0.0)
    width = np.broadcast_to(h, x0.shape)
    times = _quadrature(width, x0, u0, w, x0 <= x_end, _NODES, _WEIGHTS)
    steep = _steep(x0, x[:, 1:])  # by the grid's x at both ends, as ``JerkTimeScaling._times_to`` decides
    if steep.any():
        times[steep] = _quadrature(width[steep], x0[steep], u0[steep], w[steep], (x0 <= x_end)[steep], _FINE_NODES, _FINE_WEIGHTS)
    with np.errstate(divide="ignore", invalid="ignore"):
        if rest_start:
            times[:, 0] = np.cbrt(6.0 * h[0] / sigma_start)
        if rest_end:
            times[:, -1] = np.cbrt(6.0 * h[-1] / sigma_end)
    return times


@dataclass(frozen=True)
class JerkTimeScaling(TimeScaling):
    """s(t) with x = sd^2 quadratic and sdd linear in s on each grid interval (module docstring).

    Attributes:
        s: Grid, shape (K + 1,), from 0 to 1.
        sd: Path speed at the grid points, shape (K + 1,), in 1/s.
        u: Path acceleration at the grid points, shape (K + 1,), in 1/s^2.
        rest_start, rest_end: Whether the first (last) interval starts (ends) at rest with
            constant path jerk.
        optimality_gap, gap_basis: (``TimeScaling``) the estimated relative distance of the
            duration from the optimum of the method's problem, and how it was obtained.
    """

    # Always given; a default only because the base class's fields have defaults.
    u: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rest_start: bool = False
    rest_end: bool = False

    @cached_property
    def _grid(self) -> _Grid:
        """The arrays every evaluation reads, computed once per timing."""
        h = np.diff(self.s)
        x = self.sd**2
        w = np.diff(self.u) / h
        sigma_start = sigma_end = 0.0
        if self.rest_start:
            w[0] = 2.0 * x[1] / (9.0 * h[0] ** 2)
            sigma_start = (2.0 / 9.0) * x[1] ** 1.5 / h[0] ** 2
        if self.rest_end:
            w[-1] = 2.0 * x[-2] / (9.0 * h[-1] ** 2)
            sigma_end = (2.0 / 9.0) * x[-2] ** 1.5 / h[-1] ** 2
        return _Grid(h, x, w, sigma_start, sigma_end)

    @property
    def _x(self) -> np.ndarray:
        return self._grid.x

    @property
    def _w(self) -> np.ndarray:
        """du/ds of each interval (K,); for an interval at rest, its value at the other end."""
        return self._grid.w

    def _sigma(self, end: bool) -> float:
        """Path jerk of the interval at rest at the start (``end`` False) or the end."""
        return self._grid.sigma_end if end else self._grid.sigma_start

    def _rest_masks(self, interval: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Where ``interval`` is the interval at rest at the start, at the end (``None``: nowhere)."""
        first = interval == 0 if self.rest_start else None
        last = interval == len(self.s) - 2 if self.rest_end else None
        return (first if first is not None and first.any() else None), (last if last is not None and last.any() else None)

    def _state(self, interval: np.ndarray, offset: np.ndarray):
        """x, u and sddd at ``offset`` = s - s_i into ``interval`` (arrays of equal shape)."""
        grid = self._grid
        h = grid.h[interval]
        x0, u0 = grid.x[interval], self.u[interval]
        w = grid.w[interval]
        x = np.maximum(x0 + 2.0 * u0 * offset + w * offset**2, 0.0)
        u = u0 + w * offset
        sddd = w * np.sqrt(x)
        for mask, end in zip(self._rest_masks(interval), (False, True)):
            if mask is None:
                continue
            sigma = self._sigma(end)
            # Distance from the rest point, and the time from (or to) it.
            gap = offset[mask] if not end else h[mask] - offset[mask]
            tau = np.cbrt(6.0 * np.maximum(gap, 0.0) / sigma)
            x[mask] = (0.5 * sigma * tau**2) ** 2
            u[mask] = sigma * tau if not end else -sigma * tau
            sddd[mask] = sigma
        return x, u, sddd

    @cached_property
    def interval_times(self) -> np.ndarray:
        """Time spent in each interval, shape (K,), in s."""
        return interval_times(self.s, self._x[None, :], self.u[None, :], self.rest_start, self.rest_end)[0]

    def _times_to(self, interval: np.ndarray, offset: np.ndarray) -> np.ndarray:
        """Time from the start of ``interval`` to ``offset`` into it."""
        offset = np.asarray(offset, dtype=float)
        # With h = offset tau^2 from the end where x is smaller, dh / sqrt(x) = 2 offset tau
        # dtau / sqrt(x) stays smooth where x nears zero (x grows linearly from there).
        grid = self._grid
        x_start = grid.x[interval]
        x_end, _, _ = self._state(interval, offset)
        u0, w = self.u[interval], grid.w[interval]
        times = _quadrature(offset, x_start, u0, w, x_start <= x_end, _NODES, _WEIGHTS)
        # Steep by the whole interval's ends, so that the rule does not change along it.
        steep = _steep(x_start, grid.x[interval + 1])
        if steep.any():
            times[steep] = _quadrature(
                offset[steep], x_start[steep], u0[steep], w[steep], (x_start <= x_end)[steep], _FINE_NODES, _FINE_WEIGHTS,
            )
        first, last = self._rest_masks(interval)
        if first is not None:
            times[first] = np.cbrt(6.0 * offset[first] / self._sigma(False))
        if last is not None:
            sigma, h = self._sigma(True), grid.h[interval[last]]
            times[last] = np.cbrt(6.0 * h / sigma) - np.cbrt(6.0 * np.maximum(h - offset[last], 0.0) / sigma)
        return np.where(offset > 0.0, times, 0.0)

    @cached_property
    def t(self) -> np.ndarray:
        """Time at each grid point, shape (K + 1,), in s."""
        return np.concatenate(([0.0], np.cumsum(self.interval_times)))

    @property
    def sdd(self) -> np.ndarray:
        """Path acceleration at the start of each interval, shape (K,), in 1/s^2."""
        return self.u[:-1]

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        grid_t = self.t
        t = np.clip(np.asarray(t, dtype=float), 0.0, grid_t[-1])
        interval = np.clip(np.searchsorted(grid_t, t, side="right") - 1, 0, len(self.s) - 2)
        target = t - grid_t[interval]
        h = np.diff(self.s)[interval]
        # Newton on the time to an offset (dt/ds = 1 / sd), kept inside the interval; a sample
        # leaves the iteration where it has converged.
        low, high = np.zeros_like(h), h.copy()
        offset = np.clip(target * np.sqrt(np.maximum(self._x[interval], 1e-300)), 0.0, h)
        active = np.arange(len(t))
        for _ in range(60):
            where, at = interval[active], offset[active]
            with np.errstate(invalid="ignore"):
                error = np.nan_to_num(self._times_to(where, at) - target[active], nan=0.0)
            low[active] = np.where(error < 0, at, low[active])
            high[active] = np.where(error > 0, at, high[active])
            x, _, _ = self._state(where, at)
            with np.errstate(invalid="ignore"):
                step = at - error * np.sqrt(x)
            inside = (step > low[active]) & (step < high[active])
            moving = np.abs(error) > 1e-13 * max(1.0, grid_t[-1])
            offset[active] = np.where(moving, np.where(inside, step, 0.5 * (low[active] + high[active])), at)
            active = active[moving]
            if active.size == 0:
                break
        x, u, _ = self._state(interval, offset)
        return np.minimum(self.s[interval] + offset, self.s[interval + 1]), np.sqrt(x), u

    def dense_states(self, points_per_interval: int = 3, reference: np.ndarray | None = None) -> DenseStates:
        base = TimeScaling.dense_states(self, points_per_interval, reference)
        interval = base.interval
        assert interval is not None  # TimeScaling's dense states carry their intervals
        offset = base.s - self.s[interval]
        x, u, sddd = self._state(interval, offset)
        return DenseStates(s=base.s, sd=np.sqrt(x), sdd=u, sddd=sddd, left=base.left, interval=interval)

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        interval = np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.s) - 2)
        x, _, _ = self._state(interval, s - self.s[interval])
        return np.sqrt(x)
