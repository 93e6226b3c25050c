"""Newton's method on residual functions with a finite-difference Jacobian, for the switching-time
parameterization of a bang-bang motion (``toptraj.planners.generators.collocation.switching``, after Jeong & Lee
section 4.3): the goal equations r(theta) = 0 (2 n_dof of them) in the unknowns theta (the
switching times and the duration T, in s), solved with some unknowns held, and the shortest T
along a one-dimensional family of solutions by the secant method on dT/dp, dT/dp from the
implicit function theorem.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def jacobian(function: Callable[[np.ndarray], np.ndarray], x: np.ndarray, value: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """Forward differences of ``function`` at ``x`` (where it is ``value``)."""
    columns = []
    for i in range(len(x)):
        shifted = x.copy()
        shifted[i] += step
        columns.append((function(shifted) - value) / step)
    return np.array(columns).T


def newton(function: Callable[[np.ndarray], np.ndarray], x: np.ndarray, tolerance: float, iterations: int = 30) -> np.ndarray:
    """Gauss-Newton steps of least norm (the pseudo-inverse: square or with more unknowns than
    equations) towards function(x) = 0, halved while they do not reduce the residual."""
    value = function(x)
    for _ in range(iterations):
        norm = np.abs(value).max()
        if norm < tolerance:
            break
        step = np.linalg.lstsq(jacobian(function, x, value), -value, rcond=None)[0]
        for _ in range(20):
            trial = x + step
            trial_value = function(trial)
            if np.abs(trial_value).max() < norm:
                x, value = trial, trial_value
                break
            step = step / 2
        else:
            break
    return x


def held_newton(function: Callable[..., np.ndarray], theta: np.ndarray, held: np.ndarray, tolerance: float) -> np.ndarray:
    """Newton's method on the unknowns other than ``held`` (indices), which keep their values."""
    others = np.setdiff1d(np.arange(len(theta)), held)

    def reduced(x):
        full = theta.copy()
        full[others] = x
        return function(full)

    result = theta.copy()
    result[others] = newton(reduced, theta[others], tolerance)
    return result


#: First trial step (s) of the held switching time, and the largest step of the secant method.
SECANT_FIRST, SECANT_LONGEST, SECANT_TOLERANCE = 2e-3, 2e-2, 1e-8


def secant_minimum(residual: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, iterations: int = 30) -> tuple[np.ndarray, int]:
    """The shortest T along the one-dimensional family of solutions through ``theta``: the
    switching time p that the family's tangent moves most is held, and dT/dp = 0 is solved by
    the secant method, each trial corrected back onto the family by Newton's method."""
    J = jacobian(residual, theta, residual(theta))
    tangent = np.linalg.svd(J)[2][-1]
    p = int(np.argmax(np.abs(tangent[:-1])))
    others = np.setdiff1d(np.arange(len(theta)), [p])

    def slope(x):
        """dT/dp on the family at the solution x, and d(others)/dp."""
        value = residual(x)
        columns = jacobian(residual, x, value)
        derivative = -np.linalg.solve(columns[:, others], columns[:, p])
        return derivative[-1], derivative

    g, direction = slope(theta)
    previous = None
    for _ in range(iterations):
        if previous is None:
            step = -np.sign(g) * SECANT_FIRST
        else:
            curvature = (g - previous[1]) / (theta[p] - previous[0])
            step = -g / curvature if curvature > 0 else -np.sign(g) * SECANT_LONGEST
        step = float(np.clip(step, -SECANT_LONGEST, SECANT_LONGEST))
        trial = theta.copy()
        trial[p] += step
        trial[others] += direction * step
        trial = held_newton(residual, trial, np.array([p]), 1e-10)
        if np.abs(residual(trial)).max() > 1e-7:
            break
        previous = (theta[p], g)
        theta = trial
        g, direction = slope(theta)
        if abs(step) < SECANT_TOLERANCE:
            break
    return theta, p
