"""What a collocation tells of its work (``toptraj.planners.generators.collocation.generator``):
the figures of the collocation whose motion is returned, how its switching times were found, and
the estimated gap of the motion to the optimum of its own problem (Jeong & Lee section 4)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from toptraj.planners.problem.methods import Report

if TYPE_CHECKING:
    from toptraj.planners.generators.collocation.motion import CollocationResult, StatedGap
    from toptraj.planners.timing.base import PathTiming


@dataclass(frozen=True)
class CollocationReport(Report):
    """The collocation's figures.

    Attributes:
        cost: Its objective J, the integral of (1 + beta |tau|^2) dt (s), on its own grid.
        duration: Its duration T (s), on its own grid.
        status: The NLP solver's final status (IPOPT's).
        iterations: The NLP solver's iterations.
        initial_guess: The initial guess whose optimum won.
        solve_s: Seconds the solves took.
        switching: Minimum time only: ``"refined"`` (exact bang-bang controls,
            ``toptraj.planners.generators.collocation.switching``) or ``"read off the samples"``;
            ``None`` with a torque weight.
        optimality_gap: Estimated relative distance of the returned motion's objective from
            the optimum of its problem; ``None`` when not estimated.
        gap_basis: How ``optimality_gap`` was estimated.
    """

    cost: float
    duration: float
    status: str
    iterations: int
    initial_guess: str
    solve_s: float
    switching: str | None
    optimality_gap: float | None
    gap_basis: str

    @classmethod
    def of(cls, collocation: CollocationResult, switching: str | None, gap: StatedGap | PathTiming) -> CollocationReport:
        """The report of ``collocation`` (a ``CollocationResult``) whose motion is returned,
        with the gap of ``gap`` (the returned motion's against the collocation's extrapolated
        optimum, or that of the refined motion that replaced it: anything with
        ``optimality_gap`` and ``gap_basis``)."""
        return cls(
            cost=collocation.cost, duration=float(collocation.t[-1]), status=collocation.status,
            iterations=collocation.iterations, initial_guess=collocation.initial_guess, solve_s=collocation.solve_s,
            switching=switching, optimality_gap=gap.optimality_gap, gap_basis=gap.gap_basis,
        )
