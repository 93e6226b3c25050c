"""What ``plan`` returns: samples and diagnostics of one timed motion."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.timing.base import Binding
from planners.trajectory import Samples


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
    (``planners.kinematics.conditioning``), with the characteristic length L in m."""

    kappa_min: float
    kappa_max: float
    characteristic_length: float


@dataclass(frozen=True)
class PlannedTrajectory:
    """What ``plan`` returns: samples and diagnostics of one timed path."""

    robot: str
    method: str
    joint_names: tuple[str, ...]
    duration: float
    samples: Samples
    phase_plane: PhasePlane
    peak_utilization: dict[str, np.ndarray]
    solve_ms: float
    warnings: tuple[str, ...]
    binding: Binding | None = None
    conditioning: Conditioning | None = None
    cost: float | None = None
    solver: dict | None = None
