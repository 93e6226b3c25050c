"""Kinematic conditioning: the condition number of the Jacobian in the Frobenius norm (Angeles,
*Fundamentals of Robotic Mechanical Systems*, ch. 5, problems 5.14-5.17).

With the weighted norm ||J|| = sqrt(tr(J W J^T)), W = 1 / n, and singular values sigma_i,

    kappa_F = ||J|| ||J^-1|| = (1 / n) sqrt(sum sigma_i^2 * sum sigma_i^-2),

1 for an isotropic Jacobian, infinite at a singularity. A Jacobian mixing rotations (rad) and
translations (m) is made dimensionally homogeneous by dividing its translational rows by a
characteristic length L. Arms of at most three joints are conditioned on the position of their
end effector alone (3 rows); longer arms on the whole twist (6 rows, translation over L), using
the n largest singular values when n < 6.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.kinematics.condition_kernels import gram_condition_numbers
from toptraj.planners.kinematics.frame_jacobians import frame_jacobians
from toptraj.robots import Robot

#: A warning is raised above this condition number.
NEAR_SINGULAR_KAPPA = 100.0


#: Condition number up to which ``frobenius_condition_number`` takes the Gram matrix's inverse;
#: beyond, the singular values (the Gram matrix squares the condition number, and its inverse
#: loses about kappa^2 * 1e-16 of relative accuracy: 1e-10 at this bound).
GRAM_KAPPA = 1e3


def frobenius_condition_number(jacobian: np.ndarray) -> float | np.ndarray:
    """kappa_F of a full-rank (m x n) Jacobian over its min(m, n) singular values; infinite when
    rank-deficient (sigma_min <= 1e-12 sigma_max). A stack (k, m, n) gives k values.

    With G = J^T J (m >= n) or J J^T (m < n), the k = min(m, n) squared singular values are G's
    eigenvalues, so sum sigma_i^2 = tr G and sum sigma_i^-2 = tr G^-1: the small Gram matrices'
    Cholesky factors, compiled (``toptraj.planners.kinematics.condition_kernels``), instead of their
    singular value decompositions. Where that gives kappa_F > ``GRAM_KAPPA`` (or G is not
    positive definite), the value comes from the singular values instead, which also decide
    rank deficiency.
    """
    jacobian = np.asarray(jacobian, dtype=float)
    stack = np.ascontiguousarray(jacobian.reshape((-1, *jacobian.shape[-2:])))
    kappa = np.empty(len(stack))
    gram_condition_numbers(stack, kappa)
    trusted = kappa <= GRAM_KAPPA  # False where not a number, too
    if not trusted.all():
        exact = ~trusted
        kappa[exact] = singular_value_condition_numbers(stack[exact])
    if jacobian.ndim == 2:
        return float(kappa[0])
    return kappa.reshape(jacobian.shape[:-2])


def singular_value_condition_numbers(stack: np.ndarray) -> np.ndarray:
    """kappa_F = sqrt(sum sigma_i^2 sum sigma_i^-2) / k of every matrix of ``stack`` (s, m, n)
    over its k = min(m, n) singular values (numpy's LAPACK SVD, values only); inf where one is
    rank-deficient to rounding (sigma_min <= 1e-12 sigma_max). Shape (s,)."""
    values = np.linalg.svd(stack, compute_uv=False)  # (s, k), descending
    largest, smallest = values[:, 0], values[:, -1]
    with np.errstate(divide="ignore", invalid="ignore"):  # a zero matrix: inf, then set below
        kappa = np.sqrt(np.sum(values * values, axis=1) * np.sum(1.0 / (values * values), axis=1)) / values.shape[1]
    kappa[smallest <= 1e-12 * np.maximum(largest, 1e-300)] = np.inf
    return kappa


def characteristic_length(robot: Robot) -> float:
    """Default L: distance from the first joint to the end effector at the neutral posture
    (``Robot.neutral_reach``), at least 5 cm."""
    return max(robot.neutral_reach, 0.05)


def task_jacobian(robot: Robot, q: np.ndarray, frame_id: int, length: float) -> np.ndarray:
    """The end effector's Jacobian at ``q`` (n_dof,) as conditioned here: 3 translational rows
    for arms of up to three joints; else the translational rows divided by ``length`` over the
    angular rows (the order of the rows changes no singular value)."""
    return task_jacobians(robot, np.atleast_2d(q), frame_id, length)[0]


def task_jacobians(robot: Robot, q: np.ndarray, frame_id: int, length: float) -> np.ndarray:
    """``task_jacobian`` at every row of ``q`` (n_samples, n_dof): shape (n_samples, 3 or 6,
    n_dof)."""
    jacobians = frame_jacobians(robot, frame_id, q)
    if robot.dof <= 3:
        return jacobians[:, :3]
    jacobians[:, :3] /= length
    return jacobians


def conditioning_along(robot: Robot, q: np.ndarray, rows: np.ndarray) -> tuple[float, float, float, int]:
    """(kappa_min, kappa_max, L, index of kappa_max in ``q``) over the rows ``rows`` (m,) of
    ``q`` (n_samples, n_dof), chosen by the caller (e.g. evenly spaced)."""
    length = characteristic_length(robot)
    frame_id = robot.frame_id(robot.end_effector)
    kappas = np.atleast_1d(frobenius_condition_number(task_jacobians(robot, q[rows], frame_id, length)))
    worst = int(np.argmax(kappas))
    return float(kappas.min()), float(kappas.max()), length, int(rows[worst])
