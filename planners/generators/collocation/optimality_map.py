"""The optimality map of a two-joint arm's rest-to-rest motions with the elbow free (Jeong & Lee
section 4.3, after Geering et al. 1986): for a shoulder goal phi_b, which family of bang-bang
motions is the fastest, the elbow returning to its start (psi_b = 0, the paper's Types 1 and 2)
or turning a full revolution (psi_b = -2 pi, Types 3 and 4). The paper finds Type 1 up to
phi_b = 0.76 rad, Type 3 up to 1.76 rad and Type 4 beyond.

Families are discovered by the free-path service itself: the collocation with ``revolutions``
(the elbow free among its goal and +-2 pi) at a few anchor goals, refined to exact bang-bang
controls (``toptraj.planners.generators.collocation.switching``). Each family is then continued in phi_b, every
motion solved with the family's switching structure from the nearest one already known (steps
of at most ``CONTINUATION_STEP``); a family ends where its arcs would change order (a structure
that no longer exists). At each phi_b the fastest family wins, and a boundary between two
winners is located by bisection.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from toptraj.planners.generators.collocation.bang_bang import BangBang
from toptraj.planners.generators.collocation.collocation import _optimize_motion
from toptraj.planners.generators.collocation.switching import refine_collocation, refine_switching
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.robots import Robot

#: Largest step (rad) of phi_b between a family's solution and the next one solved from it.
CONTINUATION_STEP = 0.1


@dataclass
class Family:
    """Bang-bang motions from rest at q = 0 to rest at (phi_b, ``elbow``) with one switching
    structure, solved at the phi_b (rad) of ``solutions``; ``None`` where it does not exist.
    ``step`` (rad) is the longest continuation step."""

    robot: Robot
    elbow: float
    label: str
    solutions: dict[float, BangBang | None] = field(default_factory=dict)
    step: float = CONTINUATION_STEP

    def at(self, phi_b: float) -> BangBang | None:
        """The family's motion at ``phi_b``, continued from the nearest known one."""
        if phi_b in self.solutions:
            return self.solutions[phi_b]
        known = [phi for phi, solution in self.solutions.items() if solution is not None]
        nearest = min(known, key=lambda phi: abs(phi - phi_b))
        ended = [phi for phi, solution in self.solutions.items() if solution is None]
        if any(min(nearest, phi_b) < phi < max(nearest, phi_b) for phi in ended):
            return None  # the family ends between its nearest solution and phi_b
        steps = max(1, int(np.ceil(abs(phi_b - nearest) / self.step - 1e-9)))
        controls = self.solutions[nearest]
        for phi in np.linspace(nearest, phi_b, steps + 1)[1:]:
            assert controls is not None  # known solutions are not None; a None ends the loop below
            motion = refine_switching(
                self.robot, self.robot.limits.torque, np.zeros(2), np.array([phi, self.elbow]), controls
            )
            controls = None if motion is None or _structure(motion.controls) != self.label else motion.controls
            self.solutions[float(phi)] = controls
            if controls is None:
                break
        self.solutions[phi_b] = controls
        return controls


def _structure(controls: BangBang) -> str:
    return controls.label()


def discover(robot: Robot, anchors: Iterable[float]) -> list[Family]:
    """The families of the free-path answers (collocation with ``revolutions``, refined) at the
    shoulder goals ``anchors`` (rad), one per distinct elbow goal and switching structure."""
    families: list[Family] = []
    for phi_b in anchors:
        motion = FreeMotion(np.zeros(2), np.array([phi_b, 0.0]), revolutions=True)
        collocation = _optimize_motion(robot, robot.limits, motion, 0.0, 1000)
        refined = refine_collocation(robot, robot.limits, motion, collocation)
        if refined is None:
            continue
        elbow = _turns(float(collocation.q[-1][1]))
        label = _structure(refined.controls)
        family = next((f for f in families if f.label == label and f.elbow == elbow), None)
        if family is None:
            family = Family(robot, elbow, label)
            families.append(family)
        family.solutions[float(phi_b)] = refined.controls
    return families


def _turns(angle: float) -> float:
    """``angle`` (rad), which the collocation reaches to within its tolerance, as the whole
    number of turns it stands for."""
    return 2 * np.pi * round(angle / (2 * np.pi))


def fastest(families: list[Family], phi_b: float) -> tuple[Family | None, float]:
    """The family with the shortest motion to ``phi_b`` and its duration T (s)."""
    best, duration = None, np.inf
    for family in families:
        controls = family.at(phi_b)
        if controls is not None and controls.duration < duration:
            best, duration = family, controls.duration
    return best, duration


def boundary(families: list[Family], below: Family, lower: float, upper: float, width: float) -> tuple[float, float]:
    """The bracket [a, b] (rad), at most ``width`` wide, where the fastest family changes from
    ``below`` (fastest at ``lower``) to another (at ``upper``), by bisection."""
    if fastest(families, lower)[0] is not below or fastest(families, upper)[0] is below:
        raise ValueError(f"the fastest family must change between {lower} and {upper} rad")
    while upper - lower > width:
        middle = 0.5 * (lower + upper)
        if fastest(families, middle)[0] is below:
            lower = middle
        else:
            upper = middle
    return lower, upper


def sweep(families: list[Family], phis: Iterable[float]) -> list[tuple[float, dict[str, float | None], str | None]]:
    """Per shoulder goal (rad): each family's duration (s, ``None`` where it does not exist),
    keyed by elbow goal and structure, and the fastest family's key."""
    rows = []
    for phi_b in phis:
        durations = {}
        for family in families:
            controls = family.at(float(phi_b))
            durations[key(family)] = None if controls is None else controls.duration
        best = fastest(families, float(phi_b))[0]
        rows.append((float(phi_b), durations, None if best is None else key(best)))
    return rows


def key(family: Family) -> str:
    """The map's key of ``family``: its elbow angle psi_b (rad) and its label."""
    return f"psi_b {family.elbow:+.4f}: {family.label}"
