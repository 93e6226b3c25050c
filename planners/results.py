"""What ``plan`` returns: samples and diagnostics of one timed motion."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.errors import NonFinite
from toptraj.planners.timing.base import Binding
from toptraj.planners.trajectory import Samples, SwitchingTimes

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from toptraj.planners.collision import Clearance
    from toptraj.planners.generators.collocation.report import CollocationReport
    from toptraj.planners.generators.search.report import SearchReport


@dataclass(frozen=True)
class PhasePlane:
    """The (s, sd) picture: the timing's path speed and the maximum velocity curve, in 1/s."""

    s: np.ndarray
    sd: np.ndarray
    sd_max: np.ndarray
    switch_points: tuple[tuple[float, str], ...]


@dataclass(frozen=True)
class Conditioning:
    """Frobenius condition number of the end effector's Jacobian along the trajectory
    (``toptraj.planners.kinematics.conditioning``), with the characteristic length L in m."""

    kappa_min: float
    kappa_max: float
    characteristic_length: float


@dataclass(frozen=True)
class Accuracy:
    """The answer's estimated relative distance from the converged optimum of its method's
    problem (``toptraj.planners.runner.accuracy``): ``relative_gap`` (``None`` when not estimated) and how it
    was estimated, or why not (``basis``)."""

    relative_gap: float | None
    basis: str


@dataclass(frozen=True)
class ZoneReport:
    """Where a zone lies on the path and whether its limits bound the timing: ``ranges``, the
    closed s-ranges it covers; ``peak``, the largest ratio inside it of a quantity it limits to
    its limit there; ``binding``, whether that peak reaches
    ``toptraj.planners.constraints.zones.BINDING_SHARE``."""

    index: int
    ranges: tuple[tuple[float, float], ...]
    peak: float
    binding: bool


@dataclass(frozen=True)
class PlannedTrajectory:
    """What ``plan`` returns: samples and diagnostics of one timed path."""

    robot: str
    method: str
    joint_names: tuple[str, ...]
    duration: float
    samples: Samples
    phase_plane: PhasePlane
    #: Peak |value| / limit per kind, (n_dof,) each (a tool limit's: shape ()); ``nan`` for a
    #: joint and kind without a finite limit.
    peak_utilization: dict[str, np.ndarray]
    solve_ms: float
    warnings: tuple[str, ...]
    #: The stated accuracy, which the runner gives every answer of either family of methods.
    accuracy: Accuracy
    binding: Binding | None = None
    conditioning: Conditioning | None = None
    cost: float | None = None
    #: The collocation's figures (timing method ``collocation``).
    solver: CollocationReport | None = None
    clearance: Clearance | None = None
    #: Free paths with time-optimal (bang-bang) torques: the instants where each saturated
    #: torque changes sides.
    switching_times: SwitchingTimes | None = None
    #: What the global search did (timing method ``search``).
    search: SearchReport | None = None
    zones: tuple[ZoneReport, ...] | None = None


def require_finite(method: str, **quantities: ArrayLike | None) -> None:
    """NonFinite (a TimingFailed) unless every number of every named quantity (arrays, scalars or ``None``)
    is finite: a timing whose numbers overflowed is a failure of the method, never an answer."""
    for name, values in quantities.items():
        if values is None:
            continue
        array = np.asarray(values, dtype=float)
        if np.isfinite(array).all():
            continue
        bad = np.flatnonzero(~np.isfinite(array.ravel()))
        if bad.size:
            raise NonFinite(
                f"timing method {method!r} failed: its {name} holds {array.ravel()[bad[0]]} "
                f"({bad.size} non-finite values); the request's durations, limits or boundary states "
                "lie too far apart for this method",
                method=method, quantity=name, count=int(bad.size),
            )
