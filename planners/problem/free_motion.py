"""What a caller asks when the planner finds the path itself: a free motion from a start to a
goal (the collocation, Jeong & Lee section 4, and the global search, section 2)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Collocation intervals K when a request names none (Jeong & Lee use 30 in section 4).
DEFAULT_INTERVALS = 30


@dataclass(frozen=True)
class FreeMotion:
    """Start and goal configurations (n_dof,), optional boundary velocities (rad/s), the number
    of collocation intervals, and whether continuous joints may reach their goal one revolution
    either way (``revolutions``)."""

    start: np.ndarray
    goal: np.ndarray
    start_velocity: np.ndarray | None = None
    end_velocity: np.ndarray | None = None
    intervals: int = DEFAULT_INTERVALS
    revolutions: bool = True
