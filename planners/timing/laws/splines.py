r"""Cubic splines through equally spaced supporting points (Angeles, *Fundamentals of Robotic
Mechanical Systems*, sec. 6.6 and the solutions to problems 6.1 (c) and 6.2).

On the supporting points x_k = k / (N - 1), k = 0 .. N - 1 (spacing h = 1 / (N - 1)), a cubic
spline is fixed by its values s_k and its second derivatives s''_k; on [x_k, x_{k+1}], with
u = x - x_k (eqs. 6.55a-d),

.. math::
    s(x) = A_k u^3 + B_k u^2 + C_k u + D_k,\quad A_k = (s''_{k+1} - s''_k) / (6 h),\quad
    B_k = s''_k / 2,\quad C_k = (s_{k+1} - s_k) / h - h (s''_{k+1} + 2 s''_k) / 6,\quad D_k = s_k,

and continuity of s' at the interior points gives the equations (6.58a) A s'' = 6 C s, rows
h s''_{k-1} + 4 h s''_k + h s''_{k+1} = 6 (s_{k-1} - 2 s_k + s_{k+1}) / h.

* ``periodic_spline``: s_0 = s_{N-1}, s'_0 = s'_{N-1}, s''_0 = s''_{N-1} (eqs. 79a-c, 80: the
  cyclic (N-1) x (N-1) system of problem 6.1 (c)).
* ``spline_from_accelerations``: the second derivatives given, the values sought, with s at both
  ends given (eq. 83 of problem 6.2: s = C^{-1} A s'' / 6).
* ``clamped_spline``: values and the two end slopes given (the spline a rest-to-rest time law
  needs: see ``SplineProfile``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.timing.laws.profiles import NormalizedProfile

#: Fewest supporting points: Angeles' matrices of eqs. (80) and (83) need N >= 4.
MIN_SUPPORTING_POINTS = 4
#: Most supporting points a request may ask for.
MAX_SUPPORTING_POINTS = 1000


@dataclass(frozen=True)
class UniformCubicSpline:
    """A cubic spline on ``len(values)`` equally spaced points of [0, 1].

    Attributes:
        values: s_k, shape (N,).
        second: s''_k, shape (N,).
    """

    values: np.ndarray
    second: np.ndarray

    @property
    def points(self) -> np.ndarray:
        """The supporting points x_k = k / (N - 1), shape (N,)."""
        return np.linspace(0.0, 1.0, len(self.values))

    def derivatives(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """s, s', s'' and s''' at ``x`` in [0, 1] (eqs. 6.55a-d); at a supporting point, the
        piece on its right (the last point: the last piece)."""
        x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
        n = len(self.values) - 1
        h = 1.0 / n
        k = np.clip(np.floor(x * n).astype(int), 0, n - 1)
        u = x - k * h
        s, s2 = self.values, self.second
        A = (s2[k + 1] - s2[k]) / (6 * h)
        B = s2[k] / 2
        C = (s[k + 1] - s[k]) / h - h * (s2[k + 1] + 2 * s2[k]) / 6
        return A * u**3 + B * u**2 + C * u + s[k], 3 * A * u**2 + 2 * B * u + C, 6 * A * u + 2 * B, 6 * A


def _continuity_rows(n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """The matrices of eq. (6.58a) for the interior points, A (N-2, N) and C (N-2, N), with
    A s'' = 6 C s."""
    h = 1.0 / (n_points - 1)
    A = np.zeros((n_points - 2, n_points))
    C = np.zeros((n_points - 2, n_points))
    for row in range(n_points - 2):
        A[row, row:row + 3] = np.array([1.0, 4.0, 1.0]) * h
        C[row, row:row + 3] = np.array([1.0, -2.0, 1.0]) / h
    return A, C


def _check_points(n_points: int) -> None:
    if n_points < MIN_SUPPORTING_POINTS:
        raise ValueError(f"a spline needs at least {MIN_SUPPORTING_POINTS} supporting points, got {n_points}")


def periodic_spline(values: np.ndarray) -> UniformCubicSpline:
    """The periodic cubic spline through ``values`` (shape (N,), the last equal to the first) on
    equally spaced points of [0, 1]: eq. (80), A s'' = 6 C s with the cyclic matrices of problem
    6.1 (c), A = h circ(4, 1, ..., 1) and C = circ(-2, 1, ..., 1) / h of size N - 1."""
    values = np.asarray(values, dtype=float)
    _check_points(len(values))
    if values[-1] != values[0]:
        raise ValueError("a periodic spline needs its last value equal to its first (eq. 79a)")
    m = len(values) - 1
    h = 1.0 / m
    shift = np.eye(m, k=1) + np.eye(m, k=-1)
    shift[0, -1] = shift[-1, 0] = 1.0
    A = h * (4.0 * np.eye(m) + shift)
    C = (-2.0 * np.eye(m) + shift) / h
    second = np.linalg.solve(A, 6.0 * C @ values[:-1])
    return UniformCubicSpline(values, np.append(second, second[0]))


def spline_from_accelerations(second: np.ndarray, start: float = 0.0, end: float = 0.0) -> UniformCubicSpline:
    """The cubic spline with second derivatives ``second`` (shape (N,)) at the supporting points
    and values ``start`` and ``end`` at 0 and 1: eq. (83) of problem 6.2, s = C^{-1} A s'' / 6
    for the interior values (C tridiagonal (-2, 1) / h of size N - 2, invertible)."""
    second = np.asarray(second, dtype=float)
    _check_points(len(second))
    A, C = _continuity_rows(len(second))
    known = C[:, [0, -1]] @ np.array([start, end])
    interior = np.linalg.solve(C[:, 1:-1], A @ second / 6.0 - known)
    return UniformCubicSpline(np.concatenate(([start], interior, [end])), second)


def clamped_spline(values: np.ndarray, slope_start: float, slope_end: float) -> UniformCubicSpline:
    """The cubic spline through ``values`` (shape (N,)) with s'(0) = ``slope_start`` and
    s'(1) = ``slope_end``: eq. (6.58a) at the interior points and, from eqs. (6.55), the two
    end rows 2 h s''_0 + h s''_1 = 6 ((s_1 - s_0) / h - s'_0) and
    h s''_{N-2} + 2 h s''_{N-1} = 6 (s'_{N-1} - (s_{N-1} - s_{N-2}) / h)."""
    values = np.asarray(values, dtype=float)
    _check_points(len(values))
    n = len(values)
    h = 1.0 / (n - 1)
    A_inner, C_inner = _continuity_rows(n)
    A = np.zeros((n, n))
    rhs = np.zeros(n)
    A[1:-1] = A_inner
    rhs[1:-1] = 6.0 * C_inner @ values
    A[0, :2] = [2 * h, h]
    rhs[0] = 6.0 * ((values[1] - values[0]) / h - slope_start)
    A[-1, -2:] = [h, 2 * h]
    rhs[-1] = 6.0 * (slope_end - (values[-1] - values[-2]) / h)
    return UniformCubicSpline(values, np.linalg.solve(A, rhs))


class SplineProfile(NormalizedProfile):
    """A time law approximated by a cubic spline through ``supporting_points`` equally spaced
    values of it (Angeles, problem 6.1 (c)): smooth (continuous acceleration) and with a finite,
    piecewise-constant jerk, whatever the law it approximates.

    Angeles splits s = tau + s_p and interpolates the periodic part s_p by a periodic spline
    (eqs. 79a-c). That suits a pick-and-place cycle that never stops: the spline's speed at the
    ends, 1 + s_p'(0), is not zero (0.447 for the trapezoid tau1 = 0.2, tau2 = 0.9 with eight
    points, see tests), so a rest-to-rest move would start with a jump in velocity. This law
    keeps the supporting points and eq. (79b) (equal end slopes) but pins that slope to rest,
    s'(0) = s'(1) = 0, in place of eq. (79c) (equal end curvatures): the clamped spline. The
    decomposition into linear and periodic parts then no longer matters (a cubic spline holds the
    linear part exactly).

    Raises:
        ValueError: fewer than 4 points, or a spline that would move backwards (s' < 0: too few
            points for the law's sharp changes of speed).
    """

    def __init__(self, law: NormalizedProfile, supporting_points: int):
        self.law = law
        self.name = law.name
        self.supporting_points = supporting_points
        points = np.linspace(0.0, 1.0, supporting_points)
        self.spline = clamped_spline(law.derivatives(points)[0], 0.0, 0.0)
        speed = self.spline.derivatives(np.linspace(0.0, 1.0, 20 * supporting_points + 1))[1]
        if speed.min() < -1e-12:
            raise ValueError(
                f"the cubic spline through {supporting_points} points of the {law.name} law moves backwards; "
                "use more supporting points"
            )

    @property
    def description(self) -> str:
        return f"cubic spline through {self.supporting_points} points of the {self.law.name} law"

    def knots(self) -> np.ndarray:
        return np.union1d(self.spline.points, [0.5])

    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return self.spline.derivatives(tau)
