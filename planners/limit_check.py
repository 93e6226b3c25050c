"""The dense limit check of a timed path: how close each limit comes to binding, and where a
limit is exceeded.

Along q(s) timed by s(t) (Yamamoto et al. eqs. (8), (9); jerk by one more derivative):

    qd   = q' sd
    qdd  = q' sdd + q'' sd^2
    qddd = q' sddd + 3 q'' sd sdd + q''' sd^3
    tau  = RNEA(q, qd, qdd) + D qd + F sign(qd)

evaluated at the timing's dense states (``PathTiming.dense_states``): for timings on a grid of s,
``POINTS_PER_INTERVAL`` states per grid interval, both ends and both sides of every corner. This
check is the gate every answer passes: ``planners.plan`` refines the grid where it finds a limit
exceeded, and refuses the answer when refinement cannot bring it back.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.paths.base import GeometricPath
from planners.timing.base import PathTiming
from robots import JointLimits, Robot

#: States per grid interval for the check, both ends included.
POINTS_PER_INTERVAL = 7
KINDS = ("velocity", "acceleration", "torque", "jerk")


@dataclass(frozen=True)
class Excess:
    """The largest |value| / limit of a timed path and where it occurs.

    Attributes:
        ratio: |value| / limit (1.0: the limit binds).
        kind: "velocity", "acceleration", "torque" or "jerk".
        joint: Joint index.
        s: Path parameter where it occurs.
    """

    ratio: float
    kind: str
    joint: int
    s: float


@dataclass(frozen=True)
class LimitCheck:
    """Peak utilization per limit kind and joint (shape (n_dof,) each; 0 where unlimited), the
    worst state, and the grid intervals holding a state above the threshold (empty when none,
    or when the timing has no grid)."""

    utilization: dict[str, np.ndarray]
    worst: Excess | None
    intervals_over: np.ndarray


def joint_motion(path: GeometricPath, states) -> tuple[np.ndarray, ...]:
    """q, qd, qdd and (when the states carry sddd) qddd at ``states``, each (n, n_dof), with the
    path's one-sided derivatives at corners (``states.left``)."""
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
    return q, qd, qdd, jerk


def check_limits(
    path: GeometricPath,
    timing: PathTiming,
    robot: Robot,
    limits: JointLimits,
    kinds: tuple[str, ...] = KINDS,
    threshold: float = np.inf,
) -> LimitCheck:
    """Every limit of ``limits`` (velocity, acceleration, torque, and jerk when the timing has a
    finite one) over the dense states of ``timing`` along ``path``.

    Args:
        kinds: The limits the timing must hold: ``worst`` and ``intervals_over`` look at these
            only (``utilization`` reports every kind).
        threshold: Ratio above which a state's grid interval is listed in ``intervals_over``.
    """
    states = timing.dense_states(POINTS_PER_INTERVAL)
    q, qd, qdd, jerk = joint_motion(path, states)
    values = {"velocity": qd, "acceleration": qdd, "torque": robot.inverse_dynamics(q, qd, qdd)}
    if jerk is not None:
        values["jerk"] = jerk
    utilization, worst = {}, None
    over = np.zeros(len(states.s), dtype=bool)
    for kind, value in values.items():
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.nan_to_num(np.abs(value) / getattr(limits, kind), nan=0.0, posinf=np.inf)
        utilization[kind] = ratio.max(axis=0)
        if kind not in kinds:
            continue
        index = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        if worst is None or ratio[index] > worst.ratio:
            worst = Excess(float(ratio[index]), kind, int(index[1]), float(states.s[index[0]]))
        over |= ratio.max(axis=1) > threshold
    intervals = np.empty(0, dtype=int) if states.interval is None else np.unique(states.interval[over])
    return LimitCheck(utilization, worst, intervals)
