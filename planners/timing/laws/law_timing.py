"""``LawTiming``: s(t) made of time-law segments (normalized profiles or polynomials in t), one
per stretch of path between corners, each starting where the previous one stopped."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.timing.base import Binding, DenseStates, PathTiming
from toptraj.planners.timing.laws.profiles import NormalizedProfile, polynomial_derivatives

#: Samples per segment (in normalized time) for checking limits.
SAMPLES_PER_SEGMENT = 1000


@dataclass(frozen=True)
class LawSegment:
    """One segment of s(t) from ``s_start`` to ``s_end`` in ``duration`` seconds: either a
    normalized rest-to-rest ``profile``, or a polynomial in local time with ``coefficients``
    (absolute s, for boundary speeds and accelerations)."""

    s_start: float
    s_end: float
    duration: float
    profile: NormalizedProfile | None = None
    coefficients: np.ndarray | None = None

    def states(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """s, sd, sdd, sddd at local times ``t`` in [0, duration]."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        if self.profile is not None:
            T, span = self.duration, self.s_end - self.s_start
            sigma, d1, d2, d3 = self.profile.derivatives(t / T)
            return self.s_start + span * sigma, span * d1 / T, span * d2 / T**2, span * d3 / T**3
        assert self.coefficients is not None  # a segment without a profile is a polynomial
        first, second, third, fourth = polynomial_derivatives(self.coefficients, t, 4)
        return first, second, third, fourth

    def time_at(self, s: np.ndarray) -> np.ndarray:
        """Local time at which the segment passes ``s`` (s(t) increases along a segment)."""
        s = np.asarray(s, dtype=float)
        if self.profile is not None:
            span = self.s_end - self.s_start
            return self.duration * self.profile.tau_at((s - self.s_start) / span)
        low, high = np.zeros_like(s), np.full_like(s, self.duration)
        for _ in range(50):
            middle = 0.5 * (low + high)
            below = self.states(middle)[0] < s
            low, high = np.where(below, middle, low), np.where(below, high, middle)
        return 0.5 * (low + high)

    def sample_times(self, grid: np.ndarray | None = None) -> np.ndarray:
        """Local times for checking limits: uniform, plus the profile's own knots and the
        instants at which the segment passes the values of s in ``grid`` inside it."""
        tau = np.linspace(0.0, 1.0, SAMPLES_PER_SEGMENT + 1)
        if self.profile is not None:
            tau = np.union1d(tau, self.profile.knots())
        t = tau * self.duration
        if grid is not None:
            inside = grid[(grid > self.s_start) & (grid < self.s_end)]
            t = np.union1d(t, self.time_at(inside))
        return t


@dataclass(frozen=True)
class LawTiming(PathTiming):
    """Consecutive time-law segments covering s from 0 to 1.

    Attributes:
        segments: The segments in order.
        binding: The limit that set the duration, when the method minimized it.
        grid: Values of s its limit check passes through too (the constraints' grid, which
            holds every waypoint), beside uniform samples in time; ``None``: none.
    """

    segments: tuple[LawSegment, ...]
    binding: Binding | None = None
    grid: np.ndarray | None = None

    @property
    def duration(self) -> float:
        return float(sum(segment.duration for segment in self.segments))

    def slowed(self, factor: float) -> LawTiming | None:
        """The same rest-to-rest laws, each ``factor`` times longer (velocities divide by the
        factor, accelerations by its square); ``None`` when a segment is a polynomial fitted to
        boundary speeds, which a longer duration would change."""
        if any(segment.profile is None for segment in self.segments):
            return None
        return LawTiming(
            tuple(LawSegment(seg.s_start, seg.s_end, seg.duration * factor, profile=seg.profile) for seg in self.segments),
            binding=self.binding, grid=self.grid,
        )

    @property
    def _starts(self) -> np.ndarray:
        return np.concatenate(([0.0], np.cumsum([segment.duration for segment in self.segments])))

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        starts = self._starts
        index = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.segments) - 1)
        s, sd, sdd = np.empty_like(t), np.empty_like(t), np.empty_like(t)
        for k, segment in enumerate(self.segments):
            mine = index == k
            if np.any(mine):
                values = segment.states(t[mine] - starts[k])
                s[mine], sd[mine], sdd[mine] = values[0], values[1], values[2]
        return s, sd, sdd

    def dense_states(self, points_per_interval: int = 3) -> DenseStates:
        pieces = []
        for segment in self.segments:
            t = segment.sample_times(self.grid)
            s, sd, sdd, sddd = segment.states(t)
            left = np.zeros(len(t), dtype=bool)
            left[-1] = True
            pieces.append((s, sd, sdd, sddd, left))
        return DenseStates(*(np.concatenate([piece[i] for piece in pieces]) for i in range(5)))

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        speed = np.zeros_like(s)
        for segment in self.segments:
            mine = (s >= segment.s_start) & (s <= segment.s_end)
            if np.any(mine):
                speed[mine] = segment.states(segment.time_at(s[mine]))[1]
        return speed
