"""``SegmentedTiming``: one s(t) made of the timings of a path's stretches between corners.

Each stretch [a_k, b_k] of the path is timed in its own parameter sigma in [0, 1]
(``toptraj.planners.paths.stretch``), s = a_k + w_k sigma with w_k = b_k - a_k, so

    s-dot = w_k sigma-dot,  s-ddot = w_k sigma-ddot,  s-dddot = w_k sigma-dddot,

and the stretches follow one another in time, each starting when the previous one stopped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.timing.base import Binding, DenseStates, PathTiming

#: Relative distance (of the duration, or of a second) within which an instant is a stretch's
#: start: sample times such as ``np.arange`` makes them miss it by a rounding.
STOP_ROUNDING = 1e-12


@dataclass(frozen=True)
class SegmentedTiming(PathTiming):
    """Consecutive stretch timings covering s from 0 to 1.

    Attributes:
        edges: Stretch ends in s, shape (K + 1,), from 0 to 1.
        parts: The K stretch timings, each over its own sigma in [0, 1].
    """

    edges: np.ndarray
    parts: tuple[PathTiming, ...]

    @property
    def widths(self) -> np.ndarray:
        return np.diff(self.edges)

    @property
    def starts(self) -> np.ndarray:
        """Start time of each stretch, shape (K + 1,) with the total duration last, in s."""
        return np.concatenate(([0.0], np.cumsum([part.duration for part in self.parts])))

    @property
    def duration(self) -> float:
        return float(self.starts[-1])

    @property
    def switch_points(self) -> tuple[tuple[float, str], ...]:
        return tuple(
            (float(a + w * sigma), kind)
            for a, w, part in zip(self.edges, self.widths, self.parts)
            for sigma, kind in part.switch_points
        )

    @property
    def binding(self) -> Binding | None:
        """The binding limit of the longest stretch, in the path's s."""
        slowest = int(np.argmax([part.duration for part in self.parts]))
        binding = self.parts[slowest].binding
        if binding is None:
            return None
        a, w = self.edges[slowest], self.widths[slowest]
        return Binding(binding.kind, binding.joint, float(a + w * binding.s))

    @property
    def optimality_gap(self) -> float | None:
        """The stretches' gaps weighted by their durations (of the costs, for methods that
        report one): the relative gap of the sum; ``None`` unless every stretch has one."""
        gaps = [part.optimality_gap for part in self.parts]
        known = [gap for gap in gaps if gap is not None]
        if len(known) < len(gaps):
            return None
        costs = [getattr(part, "cost", None) for part in self.parts]
        weights = [float(cost) for cost in costs if cost is not None]
        if len(weights) < len(costs):
            weights = [part.duration for part in self.parts]
        total = sum(weights)
        return sum(w * g for w, g in zip(weights, known)) / total if total > 0.0 else None

    @property
    def gap_basis(self) -> str:
        """The stretches' bases, once each (the first stretch's reason when one has no gap)."""
        missing = [part.gap_basis for part in self.parts if part.optimality_gap is None]
        bases = missing[:1] if missing else list(dict.fromkeys(part.gap_basis for part in self.parts))
        return "; ".join(basis for basis in bases if basis)

    @property
    def cost(self) -> float | None:
        """The summed cost of the stretches, for methods that report one."""
        costs = [getattr(part, "cost", None) for part in self.parts]
        known = [cost for cost in costs if cost is not None]
        return None if len(known) < len(costs) else float(sum(known))

    def at_times(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        starts = self.starts
        # An instant within rounding of a stop between stretches is the next stretch's start,
        # as the path's derivatives there are its right side's (``GeometricPath.evaluate``): the
        # last instant of the stretch before would pair its deceleration with the next
        # stretch's direction.
        index = np.searchsorted(starts, t + STOP_ROUNDING * max(1.0, self.duration), side="right") - 1
        index = np.clip(index, 0, len(self.parts) - 1)
        s, sd, sdd = np.empty_like(t), np.empty_like(t), np.empty_like(t)
        for k, part in enumerate(self.parts):
            mine = index == k
            if np.any(mine):
                sigma, sigma_d, sigma_dd = part.at_times(t[mine] - starts[k])
                w = self.widths[k]
                s[mine] = np.where(sigma >= 1.0, self.edges[k + 1], self.edges[k] + w * sigma)
                sd[mine], sdd[mine] = w * sigma_d, w * sigma_dd
        return s, sd, sdd

    def dense_states(self, points_per_interval: int = 3) -> DenseStates:
        pieces = []
        for a, b, part in zip(self.edges[:-1], self.edges[1:], self.parts):
            states = part.dense_states(points_per_interval)
            w, end = b - a, states.s >= 1.0
            pieces.append((
                np.where(end, b, a + w * states.s),
                w * states.sd,
                w * states.sdd,
                None if states.sddd is None else w * states.sddd,
                states.left | end,
            ))
        jerk = all(piece[3] is not None for piece in pieces)
        return DenseStates(
            s=np.concatenate([piece[0] for piece in pieces]),
            sd=np.concatenate([piece[1] for piece in pieces]),
            sdd=np.concatenate([piece[2] for piece in pieces]),
            sddd=np.concatenate([piece[3] for piece in pieces]) if jerk else None,
            left=np.concatenate([piece[4] for piece in pieces]),
        )

    def speed_at(self, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        speed = np.zeros_like(s)
        for a, b, part in zip(self.edges[:-1], self.edges[1:], self.parts):
            mine = (s >= a) & (s <= b)
            if np.any(mine):
                speed[mine] = (b - a) * part.speed_at((s[mine] - a) / (b - a))
        return speed
