"""A timed path: samples of t, q, qd, qdd and tau, and how close each limit came to binding.

Given the path q(s) and the time scaling s(t): qd = q' sd, qdd = q' sdd + q'' sd^2 (Yamamoto et
al. eqs. (8), (9)), and tau from the robot's inverse dynamics (RNEA plus joint friction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.paths.base import GeometricPath
from planners.timing.base import PathTiming
from robots import Robot


@dataclass(frozen=True)
class Samples:
    """Trajectory samples, rows are time: t (n,), q, qd, qdd, tau (n, n_dof), in SI units."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray


def _joint_motion(path: GeometricPath, s, sd, sdd, side: str = "right"):
    points = path.evaluate(s, side)
    qd = points.dq * sd[:, None]
    qdd = points.dq * sdd[:, None] + points.ddq * (sd**2)[:, None]
    return points.q, qd, qdd


def sample_trajectory(path: GeometricPath, scaling: PathTiming, robot: Robot, dt: float) -> Samples:
    """Samples every ``dt`` seconds from 0, plus the final instant."""
    duration = scaling.duration
    t = np.arange(0.0, duration, dt)
    if t.size == 0 or duration - t[-1] > 1e-9 * max(1.0, duration):
        t = np.append(t, duration)
    s, sd, sdd = scaling.at_times(t)
    q, qd, qdd = _joint_motion(path, s, sd, sdd)
    return Samples(t=t, q=q, qd=qd, qdd=qdd, tau=robot.inverse_dynamics(q, qd, qdd))
