"""Joint boundary states (velocity, acceleration) turned into path states (sd, sdd).

With q' = dq/ds and q'' = d2q/ds2 at an end of the path: qd = q' sd and
qdd = q' sdd + q'' sd^2 (Yamamoto et al. eqs. (8), (9)). A joint state is admissible only when
it is of that form: the velocity along the tangent, the acceleration's part off the tangent equal
to the curvature term.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from toptraj.planners.errors import InvalidRequest, WrongLength
from toptraj.planners.paths.base import GeometricPath


def finite_vector(value: ArrayLike, name: str, length: int) -> np.ndarray:
    """``value`` as a float vector of ``length`` finite numbers (InvalidRequest naming the
    library's field ``name`` otherwise)."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidRequest(name, value, rule="not_numbers") from None
    if array.shape != (length,):
        raise WrongLength(name, value, array.size, length)
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise InvalidRequest(f"{name}[{bad[0]}]", float(array[bad[0]]), rule="not_finite")
    return array


def _tolerance(vector: np.ndarray) -> float:
    return 1e-6 * max(1.0, float(np.linalg.norm(vector)))


def path_speed(path: GeometricPath, velocity: ArrayLike | None, s_end: float, name: str) -> float:
    """sd >= 0 with q'(s_end) sd equal to the joint ``velocity`` (0 when ``None``)."""
    if velocity is None:
        return 0.0
    tangent = path.evaluate(np.array([s_end])).dq[0]
    velocity = finite_vector(velocity, name, tangent.size)
    sd = float(velocity @ tangent / (tangent @ tangent))
    if np.linalg.norm(velocity - sd * tangent) > _tolerance(velocity) or sd < 0.0:
        raise InvalidRequest(name, velocity, rule="not_tangent", at_s=s_end,
                             direction=np.round(tangent / np.linalg.norm(tangent), 6).tolist())
    return sd


def path_acceleration(path: GeometricPath, acceleration: ArrayLike | None, sd: float, s_end: float, name: str) -> float | None:
    """sdd with q' sdd + q'' sd^2 equal to the joint ``acceleration`` (None when not given)."""
    if acceleration is None:
        return None
    points = path.evaluate(np.array([s_end]))
    tangent, curvature = points.dq[0], points.ddq[0]
    acceleration = finite_vector(acceleration, name, tangent.size)
    along = acceleration - curvature * sd**2
    sdd = float(along @ tangent / (tangent @ tangent))
    if np.linalg.norm(along - sdd * tangent) > _tolerance(acceleration):
        raise InvalidRequest(name, acceleration, rule="acceleration_off_path", at_s=s_end, path_speed=sd,
                             curvature_term=np.round(curvature * sd**2, 6).tolist(), tangent=np.round(tangent, 6).tolist())
    return sdd
