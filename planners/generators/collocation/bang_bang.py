"""Bang-bang controls of a free motion (Jeong & Lee section 4.3, after Geering et al. 1986):
each torque at one bound or the other between its switching times. Their structure read off
sampled torques (a collocation's), their time-reversed twin, arcs that shrank to nothing
removed, and the switching times an answer carries; the refinement of the switching times
themselves is ``toptraj.planners.generators.collocation.switching``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.trajectory import SwitchingTimes

#: A torque is saturated on one side where it lies beyond this fraction of its limit.
SATURATED = 0.5


@dataclass(frozen=True)
class BangBang:
    """Bang-bang controls: per joint, the signs of its arcs (n_arcs,), +1 or -1, and the times
    (n_arcs - 1,) in s where it changes sides, over a duration T (s)."""

    signs: tuple[np.ndarray, ...]
    switches: tuple[np.ndarray, ...]
    duration: float

    def unknowns(self) -> np.ndarray:
        return np.concatenate([*self.switches, [self.duration]])

    def with_unknowns(self, theta: np.ndarray) -> BangBang:
        cuts = np.cumsum([len(s) for s in self.switches])[:-1]
        return BangBang(self.signs, tuple(np.array(x) for x in np.split(theta[:-1], cuts)), float(theta[-1]))

    def label(self) -> str:
        return "; ".join("(" + ", ".join("max" if s > 0 else "min" for s in signs) + ")" for signs in self.signs)


def collocation_switches(
    t: np.ndarray, tau: np.ndarray, torque_limit: np.ndarray, level: float = SATURATED, every_crossing: bool = False
) -> BangBang:
    """The bang-bang structure read off sampled torques (t (n,) in s, tau (n, n_dof) in N m): per
    joint, the sides where |tau| exceeds ``level`` of its limit, and between two sides the instant where the linearly interpolated
    torque crosses zero. Its accuracy is bounded by the sampling step (the collocation's h).

    With ``every_crossing``, every zero crossing between two saturated samples is a switch (the
    arcs between them alternate in sign), so that arcs too short for any sample to saturate (the
    middle arcs of u1 in Type 3 near its boundary with Type 4, where the collocation's torque
    lingers near zero for a few instants) are kept; else only the first crossing between two
    different sides is."""
    signs, switches = [], []
    for j in range(tau.shape[1]):
        bound = level * torque_limit[j]
        side = np.where(tau[:, j] > bound, 1, np.where(tau[:, j] < -bound, -1, 0))
        saturated = np.flatnonzero(side)
        joint_signs: list = []
        joint_switches: list = []
        for k, index in enumerate(saturated):
            if joint_signs and side[index] == joint_signs[-1] and not every_crossing:
                continue
            if joint_signs:
                previous = saturated[k - 1]
                segment = tau[previous : index + 1, j]
                crossings = _crossings(segment)
                if not every_crossing:
                    crossings = crossings[:1]
                for crossing in crossings:
                    a, b = previous + crossing, previous + crossing + 1
                    joint_switches.append(t[a] + (t[b] - t[a]) * tau[a, j] / (tau[a, j] - tau[b, j]))
                    joint_signs.append(-joint_signs[-1])
                continue
            joint_signs.append(int(side[index]))
        if not joint_signs:
            joint_signs = [1 if tau[:, j].mean() >= 0 else -1]
        signs.append(np.array(joint_signs))
        switches.append(np.array(joint_switches))
    return BangBang(tuple(signs), tuple(switches), float(t[-1]))


def _crossings(values: np.ndarray) -> np.ndarray:
    """Indices i where the sign of ``values`` changes between i and i + 1, a sample exactly at
    zero counted with the sign before it (so that it crosses once, where it lies)."""
    sign = np.sign(values)
    for i in range(1, len(sign)):
        if sign[i] == 0:
            sign[i] = sign[i - 1]
    return np.flatnonzero(np.diff(sign) != 0)


def pruned(controls: BangBang) -> BangBang:
    """Arcs that shrank to nothing removed (two switches at one instant, or one at an end)."""
    signs, switches = [], []
    for joint_signs, joint_switches in zip(controls.signs, controls.switches):
        edges = np.concatenate([[0.0], joint_switches, [controls.duration]])
        keep = np.diff(edges) > 1e-9
        kept_signs = joint_signs[keep]
        kept_edges = np.concatenate([[0.0], edges[1:][keep]])
        merged_signs, merged_switches = [kept_signs[0]], []
        for sign, edge in zip(kept_signs[1:], kept_edges[1:-1]):
            if sign != merged_signs[-1]:
                merged_signs.append(sign)
                merged_switches.append(edge)
        signs.append(np.array(merged_signs))
        switches.append(np.array(merged_switches))
    return BangBang(tuple(signs), tuple(switches), controls.duration)


def mirrored(controls: BangBang) -> BangBang:
    """The time-reversed twin of a rest-to-rest bang-bang motion on an arm whose inertia depends
    on cos(q) only and without gravity (the Geering arm between stretched poses): u(t) -> -u(T - t),
    equally fast; its switching times are T - t in reverse order."""
    T = controls.duration
    return BangBang(
        tuple(-signs[::-1] for signs in controls.signs),
        tuple((T - switches)[::-1] for switches in controls.switches),
        T,
    )


def switching_times(controls: BangBang, joint_names: tuple[str, ...]) -> SwitchingTimes:
    """Where each joint's saturated torque changes sides (s)."""
    return SwitchingTimes(tuple(joint_names), tuple(np.asarray(switches, dtype=float) for switches in controls.switches))
