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

import numpy as np

from toptraj.planners.timing.base import DenseStates, TimeScaling

#: Gauss-Legendre nodes and weights on [0, 1] for the time of an interval.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(12)
_NODES, _WEIGHTS = 0.5 * (_NODES + 1.0), 0.5 * _WEIGHTS


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

    @property
    def _x(self) -> np.ndarray:
        return self.sd**2

    @property
    def _w(self) -> np.ndarray:
        """du/ds of each interval (K,); for an interval at rest, its value at the other end."""
        h = np.diff(self.s)
        w = np.diff(self.u) / h
        x = self._x
        if self.rest_start:
            w[0] = 2.0 * x[1] / (9.0 * h[0] ** 2)
        if self.rest_end:
            w[-1] = 2.0 * x[-2] / (9.0 * h[-1] ** 2)
        return w

    def _sigma(self, end: bool) -> float:
        """Path jerk of the interval at rest at the start (``end`` False) or the end."""
        h = np.diff(self.s)
        x = self._x[-2] if end else self._x[1]
        width = h[-1] if end else h[0]
        return (2.0 / 9.0) * x**1.5 / width**2

    def _rest_flags(self) -> tuple[np.ndarray, np.ndarray]:
        n = len(self.s) - 1
        first = np.zeros(n, dtype=bool)
        last = np.zeros(n, dtype=bool)
        first[0] = self.rest_start
        last[-1] = self.rest_end
        return first, last

    def _state(self, interval: np.ndarray, offset: np.ndarray):
        """x, u and sddd at ``offset`` = s - s_i into ``interval`` (arrays of equal shape)."""
        h = np.diff(self.s)[interval]
        x0, u0 = self._x[interval], self.u[interval]
        w = self._w[interval]
        first, last = (flag[interval] for flag in self._rest_flags())
        x = np.maximum(x0 + 2.0 * u0 * offset + w * offset**2, 0.0)
        u = u0 + w * offset
        sddd = w * np.sqrt(x)
        if first.any() or last.any():
            for mask, end in ((first, False), (last, True)):
                if not mask.any():
                    continue
                sigma = self._sigma(end)
                # Distance from the rest point, and the time from (or to) it.
                gap = offset[mask] if not end else h[mask] - offset[mask]
                tau = np.cbrt(6.0 * np.maximum(gap, 0.0) / sigma)
                x[mask] = (0.5 * sigma * tau**2) ** 2
                u[mask] = sigma * tau if not end else -sigma * tau
                sddd[mask] = sigma
        return x, u, sddd

    @property
    def interval_times(self) -> np.ndarray:
        """Time spent in each interval, shape (K,), in s."""
        return self._times_to(np.arange(len(self.s) - 1), np.diff(self.s))

    def _times_to(self, interval: np.ndarray, offset: np.ndarray) -> np.ndarray:
        """Time from the start of ``interval`` to ``offset`` into it."""
        offset = np.asarray(offset, dtype=float)
        # With h = offset tau^2 from the end where x is smaller, dh / sqrt(x) = 2 offset tau
        # dtau / sqrt(x) stays smooth where x nears zero (x grows linearly from there).
        x_start, _, _ = self._state(interval, np.zeros_like(offset))
        x_end, _, _ = self._state(interval, offset)
        from_start = x_start <= x_end
        tau = _NODES[None, :]
        nodes = offset[:, None] * np.where(from_start[:, None], tau**2, 1.0 - tau**2)
        x, _, _ = self._state(np.repeat(interval[:, None], len(_NODES), axis=1), nodes)
        with np.errstate(divide="ignore", invalid="ignore"):
            times = offset * (_WEIGHTS * 2.0 * tau / np.sqrt(x)).sum(axis=1)
        first, last = (flag[interval] for flag in self._rest_flags())
        h = np.diff(self.s)[interval]
        if first.any():
            sigma = self._sigma(False)
            times[first] = np.cbrt(6.0 * offset[first] / sigma)
        if last.any():
            sigma = self._sigma(True)
            times[last] = np.cbrt(6.0 * h[last] / sigma) - np.cbrt(6.0 * np.maximum(h[last] - offset[last], 0.0) / sigma)
        return np.where(offset > 0.0, times, 0.0)

    @property
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
        # Newton on the time to an offset (dt/ds = 1 / sd), kept inside the interval.
        low, high = np.zeros_like(h), h.copy()
        offset = np.clip(target * np.sqrt(np.maximum(self._x[interval], 1e-300)), 0.0, h)
        for _ in range(60):
            with np.errstate(invalid="ignore"):
                error = np.nan_to_num(self._times_to(interval, offset) - target, nan=0.0)
            low = np.where(error < 0, offset, low)
            high = np.where(error > 0, offset, high)
            x, _, _ = self._state(interval, offset)
            with np.errstate(invalid="ignore"):
                step = offset - error * np.sqrt(x)
            inside = (step > low) & (step < high)
            offset = np.where(inside, step, 0.5 * (low + high))
            if np.all(np.abs(error) <= 1e-13 * max(1.0, grid_t[-1])):
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
