"""``JerkSegmentsTiming``: s(t) made of consecutive segments of constant path jerk, the form of
every time-optimal jerk-limited motion whose limits do not change along the path (Berscheid &
Kroeger's seven phases), and the result of the jerk-limited timing's polish
(``toptraj.planners.timing.jerk.polish``).

In segment k, of duration tau_k and path jerk sigma_k, from the state (s_k, v_k, a_k) at its
start, at local time t:

    s = s_k + v_k t + a_k t^2 / 2 + sigma_k t^3 / 6,   sd = v_k + a_k t + sigma_k t^2 / 2,
    sdd = a_k + sigma_k t,                            sddd = sigma_k.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.timing.base import DenseStates, PathTiming

#: States per segment for the dense limit check.
STATES_PER_SEGMENT = 120


def segment_starts(durations: np.ndarray, jerks: np.ndarray, start: tuple[float, float, float]) -> np.ndarray:
    """(s, sd, sdd) at the start of every segment and at the end of the last: shape (M + 1, 3)."""
    states = np.empty((len(durations) + 1, 3))
    states[0] = start
    for k, (tau, sigma) in enumerate(zip(durations, jerks)):
        s, v, a = states[k]
        states[k + 1] = (
            s + v * tau + a * tau**2 / 2 + sigma * tau**3 / 6,
            v + a * tau + sigma * tau**2 / 2,
            a + sigma * tau,
        )
    return states


@dataclass(frozen=True)
class JerkSegmentsTiming(PathTiming):
    """Segments of constant path jerk covering s from 0 to 1.

    Attributes:
        durations: tau_k, shape (M,), in s.
        jerks: sigma_k, shape (M,), in 1/s^3.
        start: (s, sd, sdd) at t = 0.
        optimality_gap: Estimated relative distance of the duration from the optimum
            of the method's problem (``PathTiming.optimality_gap``); ``None`` when unknown.
        gap_basis: How that estimate was obtained (``PathTiming.gap_basis``).
    """

    durations: np.ndarray
    jerks: np.ndarray
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    optimality_gap: float | None = None
    gap_basis: str = ""

    @property
    def starts(self) -> np.ndarray:
        return segment_starts(self.durations, self.jerks, self.start)

    @property
    def duration(self) -> float:
        return float(np.sum(self.durations))

    def _states(self, t: np.ndarray):
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        edges = np.concatenate(([0.0], np.cumsum(self.durations)))
        k = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(self.durations) - 1)
        local = t - edges[k]
        s0, v0, a0 = self.starts[k].T
        sigma = self.jerks[k]
        s = s0 + v0 * local + a0 * local**2 / 2 + sigma * local**3 / 6
        sd = v0 + a0 * local + sigma * local**2 / 2
        sdd = a0 + sigma * local
        return np.clip(s, 0.0, 1.0), np.maximum(sd, 0.0), sdd, sigma

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, sd, sdd, _ = self._states(t)
        return s, sd, sdd

    def dense_states(self, points_per_interval: int = 3) -> DenseStates:
        fractions = np.linspace(0.0, 1.0, STATES_PER_SEGMENT + 1)
        starts = self.starts
        pieces = []
        for k, (tau, sigma) in enumerate(zip(self.durations, self.jerks)):
            local = fractions * tau
            s0, v0, a0 = starts[k]
            s = s0 + v0 * local + a0 * local**2 / 2 + sigma * local**3 / 6
            sd = v0 + a0 * local + sigma * local**2 / 2
            sdd = a0 + sigma * local
            left = np.zeros(len(local), dtype=bool)
            left[-1] = True
            pieces.append((np.clip(s, 0.0, 1.0), np.maximum(sd, 0.0), sdd, np.full(len(local), sigma), left))
        return DenseStates(*(np.concatenate([piece[i] for piece in pieces]) for i in range(5)))

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        low, high = np.zeros_like(s), np.full_like(s, self.duration)
        for _ in range(60):
            middle = 0.5 * (low + high)
            below = self._states(middle)[0] < s
            low, high = np.where(below, middle, low), np.where(below, high, middle)
        return self._states(0.5 * (low + high))[1]
