"""A timed path: samples of t, q, qd, qdd and tau, and how close each limit came to binding.

Given the path q(s) and the time scaling s(t): qd = q' sd, qdd = q' sdd + q'' sd^2 (Yamamoto et
al. eqs. (8), (9)), and tau from the robot's inverse dynamics (RNEA plus joint friction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.paths.base import GeometricPath
from planners.timing.base import PathTiming
from robots import JointLimits, Robot


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


def peak_utilization(
    path: GeometricPath, timing: PathTiming, robot: Robot, limits: JointLimits
) -> dict[str, np.ndarray]:
    """max |value| / limit per joint for velocity, acceleration and torque (and jerk, when the
    timing has a finite one), over the timing's dense states, both sides of every corner; 0
    where unlimited."""
    states = timing.dense_states()
    q = path(states.s)
    qd, qdd = np.empty_like(q), np.empty_like(q)
    jerk = np.empty_like(q) if states.sddd is not None else None
    for side, mask in (("right", ~states.left), ("left", states.left)):
        if not np.any(mask):
            continue
        s, sd, sdd = states.s[mask], states.sd[mask], states.sdd[mask]
        points = path.evaluate(s, side)
        qd[mask] = points.dq * sd[:, None]
        qdd[mask] = points.dq * sdd[:, None] + points.ddq * (sd**2)[:, None]
        if jerk is not None:
            jerk[mask] = (
                path.third_derivative(s, side) * (sd**3)[:, None]
                + 3.0 * points.ddq * (sd * sdd)[:, None]
                + points.dq * states.sddd[mask][:, None]
            )
    values = [("velocity", qd), ("acceleration", qdd), ("torque", robot.inverse_dynamics(q, qd, qdd))]
    if jerk is not None:
        values.append(("jerk", jerk))
    with np.errstate(divide="ignore", invalid="ignore"):
        return {
            kind: np.nan_to_num(np.max(np.abs(value), axis=0) / getattr(limits, kind), nan=0.0)
            for kind, value in values
        }
