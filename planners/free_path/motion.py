"""A free motion to plan (start and goal configurations, boundary velocities, the number of
collocation intervals) and the collocation's answer (``planners.free_path.collocation``, Jeong &
Lee section 4): the motion at its K + 1 instants with its torques, its cost and how the solver
got there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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


@dataclass(frozen=True)
class CollocationResult:
    """The optimized motion at K + 1 instants: times (K+1,), q, v, a, tau (K+1, n_dof); its cost
    J (s), the solver's status and iteration count, and the winning initial guess."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    cost: float
    status: str
    iterations: int
    initial_guess: str
    solve_s: float
