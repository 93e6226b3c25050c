"""A timed path: samples of t, q, qd, qdd and tau, and how close each limit came to binding.

Given the path q(s) and the time scaling s(t): qd = q' sd, qdd = q' sdd + q'' sd^2 (Yamamoto et
al. eqs. (8), (9)), and tau from the robot's inverse dynamics (RNEA plus joint friction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.timing.base import PathTiming
from toptraj.robots import Robot


@dataclass(frozen=True)
class Samples:
    """Trajectory samples, rows are time: t (n,), q, qd, qdd, tau (n, n_dof), in SI units, and
    the path parameter s (n,) of each (``None`` where unknown)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    s: np.ndarray | None = None


@dataclass(frozen=True)
class SwitchingTimes:
    """The instants (s) where each saturated torque of a bang-bang motion changes sides:
    ``times[j]`` (n_switches_j,), increasing, for the joint ``joint_names[j]``."""

    joint_names: tuple[str, ...]
    times: tuple[np.ndarray, ...]

    def of(self, joint: str) -> np.ndarray:
        """The switching times (s) of the joint named ``joint``."""
        return self.times[self.joint_names.index(joint)]


def _joint_motion(path: GeometricPath, s, sd, sdd, side: str = "right"):
    """q, qd, qdd and the path's tangent q' at ``s`` (each (n, n_dof)) for the path speeds
    ``sd`` and accelerations ``sdd`` (n,)."""
    points = path.evaluate(s, side)
    qd = points.dq * sd[:, None]
    qdd = points.dq * sdd[:, None] + points.ddq * (sd**2)[:, None]
    return points.q, qd, qdd, points.dq


def exact_period_scale(duration: float, dt: float) -> float:
    """The factor k >= 1 that stretches a motion of ``duration`` s to a whole number of periods
    ``dt``: k = N dt / duration with N = ceil(duration / dt), at least 1 (a float rounding of
    duration / dt to an integer counts as that integer)."""
    periods = max(1, math.ceil(duration / dt - 1e-9))
    return periods * dt / duration if duration > 0 else 1.0


def sample_trajectory(
    path: GeometricPath, scaling: PathTiming, robot: Robot, dt: float, exact_period: bool = False
) -> Samples:
    """Samples every ``dt`` seconds from 0, plus the final instant.

    With ``exact_period`` the motion is slowed uniformly by ``k = exact_period_scale(T, dt)``
    (less than 1 + dt / T) so that it ends on a sample: t_j = j dt for j = 0 .. N with N dt = k T,
    as a controller running at period ``dt`` consumes them, the final state included. Along the
    same path, s(t) becomes s(t / k): velocities scale by 1 / k, accelerations by 1 / k^2, jerks by
    1 / k^3, and a torque M q'' + C q' + g moves from its optimal value towards the gravity
    torque g of the same configuration, so every limit the optimal timing held stays held (the
    samples' own check confirms it, joint friction included)."""
    duration = scaling.duration
    if exact_period:
        k = exact_period_scale(duration, dt)
        t = dt * np.arange(round(k * duration / dt) + 1)
        s, sd, sdd = scaling.at_times(np.minimum(t / k, duration))
        sd, sdd = sd / k, sdd / k**2
    else:
        t = np.arange(0.0, duration, dt)
        if t.size == 0 or duration - t[-1] > 1e-9 * max(1.0, duration):
            t = np.append(t, duration)
        s, sd, sdd = scaling.at_times(t)
    q, qd, qdd, dq = _joint_motion(path, s, sd, sdd)
    # At rest (the first and last samples, a stop), Coulomb friction opposes the motion along the
    # path's tangent, as the planning held it: where that tangent is not zero, the torque is the
    # limit of the moving ones.
    return Samples(t=t, q=q, qd=qd, qdd=qdd, tau=robot.inverse_dynamics(q, qd, qdd, dq), s=s)
