"""The timing side of a trajectory: ``TimeScaling`` s(t), and the interface every timing method
implements (read ``PathConstraints``, return a ``TimeScaling``)."""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

import numpy as np

from planners.constraints import PathConstraints
from planners.deadline import NO_DEADLINE, Deadline
from planners.errors import TimingFailed


@dataclass(frozen=True)
class TimeScaling:
    """A time scaling s(t) with piecewise-constant path acceleration.

    Between grid points s_i and s_i+1 the path acceleration is constant,
    u_i = (sd_i+1^2 - sd_i^2) / (2 (s_i+1 - s_i)), so x = sd^2 is linear in s (the usual
    discretization of the phase plane) and each interval takes
    dt_i = 2 (s_i+1 - s_i) / (sd_i + sd_i+1).

    Attributes:
        s: Grid, shape (K + 1,), from 0 to 1.
        sd: Path speed at the grid points, shape (K + 1,), in 1/s.
        switch_points: Optional (s, kind) pairs a method found, for the response.
    """

    s: np.ndarray
    sd: np.ndarray
    switch_points: tuple[tuple[float, str], ...] = field(default=())

    def __post_init__(self):
        if np.any(~np.isfinite(self.sd)) or np.any(self.sd < 0):
            raise TimingFailed("the timing method returned a non-finite or negative path speed")
        if np.any(self.sd[:-1] + self.sd[1:] <= 0.0):
            index = int(np.flatnonzero(self.sd[:-1] + self.sd[1:] <= 0.0)[0])
            raise TimingFailed(
                f"the timing method stops the motion between s = {self.s[index]:.4g} and "
                f"s = {self.s[index + 1]:.4g}"
            )

    @property
    def sdd(self) -> np.ndarray:
        """Path acceleration of each interval, shape (K,), in 1/s^2."""
        return (self.sd[1:] ** 2 - self.sd[:-1] ** 2) / (2.0 * np.diff(self.s))

    @property
    def t(self) -> np.ndarray:
        """Time at each grid point, shape (K + 1,), in s."""
        dt = 2.0 * np.diff(self.s) / (self.sd[:-1] + self.sd[1:])
        return np.concatenate(([0.0], np.cumsum(dt)))

    @property
    def duration(self) -> float:
        """Total time, in s."""
        return float(self.t[-1])

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, sd and sdd at times ``t`` (shape (n,), clipped to [0, duration])."""
        grid_t = self.t
        t = np.clip(np.asarray(t, dtype=float), 0.0, grid_t[-1])
        interval = np.clip(np.searchsorted(grid_t, t, side="right") - 1, 0, len(self.s) - 2)
        tau = t - grid_t[interval]
        sdd = self.sdd[interval]
        sd = self.sd[interval] + sdd * tau
        s = self.s[interval] + self.sd[interval] * tau + 0.5 * sdd * tau**2
        return np.minimum(s, self.s[interval + 1]), np.maximum(sd, 0.0), sdd

    def at_path(self, interval: np.ndarray, fraction: np.ndarray):
        """s, sd and sdd at ``fraction`` (in [0, 1]) of grid interval ``interval``: both sides of
        a grid point are reached as fraction 1 of one interval and 0 of the next."""
        s0, s1 = self.s[interval], self.s[interval + 1]
        s = s0 + fraction * (s1 - s0)
        x = self.sd[interval] ** 2 + fraction * (self.sd[interval + 1] ** 2 - self.sd[interval] ** 2)
        return s, np.sqrt(np.maximum(x, 0.0)), self.sdd[interval]


class TimingMethod(abc.ABC):
    """A way to time a path: reads ``PathConstraints``, returns a ``TimeScaling``."""

    #: The ``timing.method`` name.
    name: str

    @abc.abstractmethod
    def solve(
        self,
        constraints: PathConstraints,
        sd_start: float = 0.0,
        sd_end: float = 0.0,
        deadline: Deadline = NO_DEADLINE,
    ) -> TimeScaling:
        """Time the path of ``constraints`` from path speed ``sd_start`` to ``sd_end`` (1/s)."""
