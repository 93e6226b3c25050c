"""Classical time laws: polynomial segments (lecture "Trajectory Planning": third- and
fifth-order polynomials from boundary conditions) and the normalized rest-to-rest profiles of
Angeles, *Fundamentals of Robotic Mechanical Systems*, ch. 6 (cubic, quintic 3-4-5, trapezoidal
velocity, cycloidal).

A normalized profile maps tau = t / T in [0, 1] to sigma in [0, 1] with sigma(0) = 0,
sigma(1) = 1 and zero speed at both ends; along a path segment from s_a to s_b,
s(t) = s_a + (s_b - s_a) sigma(t / T).
"""

from __future__ import annotations

import abc

import numpy as np


def cubic_coefficients(p0: float, v0: float, p1: float, v1: float, duration: float) -> np.ndarray:
    """c0..c3 of p(t) = c0 + c1 t + c2 t^2 + c3 t^3 with p(0) = p0, p'(0) = v0, p(T) = p1,
    p'(T) = v1 (the lecture's 4 x 4 system, solved in closed form)."""
    T = duration
    c2 = (3 * (p1 - p0) - (2 * v0 + v1) * T) / T**2
    c3 = (-2 * (p1 - p0) + (v0 + v1) * T) / T**3
    return np.array([p0, v0, c2, c3])


def quintic_coefficients(
    p0: float, v0: float, a0: float, p1: float, v1: float, a1: float, duration: float
) -> np.ndarray:
    """c0..c5 of the fifth-order polynomial with position, velocity and acceleration given at
    t = 0 and t = T (the lecture's six boundary conditions), solved in closed form: with
    h = p1 - p0,

    .. math::
        c_3 = (20 h - (8 v_1 + 12 v_0) T - (3 a_0 - a_1) T^2) / (2 T^3),
        c_4 = (-30 h + (14 v_1 + 16 v_0) T + (3 a_0 - 2 a_1) T^2) / (2 T^4),
        c_5 = (12 h - 6 (v_1 + v_0) T + (a_1 - a_0) T^2) / (2 T^5).
    """
    T = duration
    h = p1 - p0
    c3 = (20 * h - (8 * v1 + 12 * v0) * T - (3 * a0 - a1) * T**2) / (2 * T**3)
    c4 = (-30 * h + (14 * v1 + 16 * v0) * T + (3 * a0 - 2 * a1) * T**2) / (2 * T**4)
    c5 = (12 * h - 6 * (v1 + v0) * T + (a1 - a0) * T**2) / (2 * T**5)
    return np.array([p0, v0, 0.5 * a0, c3, c4, c5])


def polynomial_derivatives(coefficients: np.ndarray, t: np.ndarray, orders: int = 4) -> list[np.ndarray]:
    """Values of a polynomial and its first ``orders - 1`` derivatives at ``t``."""
    values = []
    poly = np.polynomial.Polynomial(coefficients)
    for _ in range(orders):
        values.append(poly(t))
        poly = poly.deriv()
    return values


class NormalizedProfile(abc.ABC):
    """sigma(tau) on [0, 1], rising from 0 to 1, at rest at both ends."""

    name: str

    @abc.abstractmethod
    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """sigma, sigma', sigma'' and sigma''' at ``tau`` (derivatives with respect to tau)."""

    def knots(self) -> np.ndarray:
        """tau values a sampling grid should hold: jumps of sigma'' or sigma''', and extrema of
        sigma' and sigma''."""
        return np.array([0.0, 0.5, 1.0])

    @property
    def description(self) -> str:
        """How an answer names the law."""
        return f"{self.name} law"

    def inner_acceleration_steps(self) -> np.ndarray:
        """tau in (0, 1) where sigma'' jumps (none for a law with continuous acceleration)."""
        return np.empty(0)

    def acceleration_steps(self) -> np.ndarray:
        """tau where the acceleration jumps, the ends included when the law leaves or reaches
        rest with sigma'' != 0 (the motion is at rest before and after it). At each of them the
        jerk is infinite, so no duration of the law holds a jerk limit."""
        ends = self.derivatives(np.array([0.0, 1.0]))[2]
        outer = np.array([0.0, 1.0])[np.abs(ends) > 1e-9]
        return np.union1d(outer, self.inner_acceleration_steps())

    def tau_at(self, sigma: np.ndarray) -> np.ndarray:
        """The tau with sigma(tau) = ``sigma`` (sigma is increasing): bisection to 1e-13."""
        sigma = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
        low, high = np.zeros_like(sigma), np.ones_like(sigma)
        for _ in range(45):
            middle = 0.5 * (low + high)
            below = self.derivatives(middle)[0] < sigma
            low = np.where(below, middle, low)
            high = np.where(below, high, middle)
        return 0.5 * (low + high)


class CubicProfile(NormalizedProfile):
    """sigma = 3 tau^2 - 2 tau^3: the rest-to-rest cubic (continuous velocity only)."""

    name = "cubic"

    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        return (
            tau * tau * (3 - 2 * tau),
            6 * tau * (1 - tau),
            6 - 12 * tau,
            np.full_like(tau, -12.0),
        )


class QuinticProfile(NormalizedProfile):
    """sigma = 10 tau^3 - 15 tau^4 + 6 tau^5: rest-to-rest with zero acceleration at the ends."""

    name = "quintic"

    def knots(self) -> np.ndarray:
        return np.array([0.0, (3 - np.sqrt(3)) / 6, 0.5, (3 + np.sqrt(3)) / 6, 1.0])

    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        return (
            tau**3 * (10 - 15 * tau + 6 * tau**2),
            30 * tau**2 * (1 - tau) ** 2,
            60 * tau * (1 - tau) * (1 - 2 * tau),
            60 * (1 - 6 * tau + 6 * tau**2),
        )


class TrapezoidalProfile(NormalizedProfile):
    """Trapezoidal speed (Angeles, problem 6.1): constant acceleration on [0, tau1], cruise at
    sigma'_max = 2 / (1 - tau1 + tau2) on [tau1, tau2], constant deceleration on [tau2, 1]."""

    name = "trapezoidal"

    def __init__(self, tau1: float = 1.0 / 3.0, tau2: float = 2.0 / 3.0):
        if not 0.0 < tau1 <= tau2 < 1.0:
            raise ValueError("trapezoidal switching fractions need 0 < tau1 <= tau2 < 1")
        self.tau1, self.tau2 = tau1, tau2
        self.peak_speed = 2.0 / (1.0 - tau1 + tau2)

    def knots(self) -> np.ndarray:
        return np.array([0.0, self.tau1, self.tau2, 1.0])

    def inner_acceleration_steps(self) -> np.ndarray:
        return np.unique([self.tau1, self.tau2])

    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        t1, t2, v = self.tau1, self.tau2, self.peak_speed
        rising = tau <= t1
        falling = tau >= t2
        # A ramp of a few ulps overflows its level to infinity; np.where evaluates every branch,
        # and the one that overflows is never the one selected.
        with np.errstate(divide="ignore", invalid="ignore"):
            accel, decel = v / t1, v / (1.0 - t2)
            sigma = np.where(
                rising,
                0.5 * accel * tau**2,
                np.where(falling, 1.0 - 0.5 * decel * (1.0 - tau) ** 2, 0.5 * accel * t1**2 + v * (tau - t1)),
            )
            speed = np.where(rising, accel * tau, np.where(falling, decel * (1.0 - tau), v))
            acceleration = np.where(rising, accel, np.where(falling, -decel, 0.0))
        return sigma, speed, acceleration, np.zeros_like(tau)


class CycloidalBlendProfile(TrapezoidalProfile):
    """The trapezoidal speed profile with cycloidal blends (Angeles, problem 6.3): the speed rises
    on [0, tau1] along half a cycloidal-motion speed (eqs. 86, 87 with u = tau / (2 tau1) in the
    cycloidal motion of eqs. 6.38a, b),

        s(tau) = (A / 2) [tau / tau1 - sin(pi tau / tau1) / pi],
        s'(tau) = (A / (2 tau1)) [1 - cos(pi tau / tau1)],

    cruises at s'_max on [tau1, tau2], and falls on [tau2, 1] along the mirror image. The text
    stops at "A is a constant to be determined"; continuity of the speed at tau1 gives
    s'(tau1) = A / tau1 = s'_max, so A = tau1 s'_max. Each blend covers half its length at
    s'_max (the mean of 1 - cos is 1), as the trapezoid's straight ramps do, so the area
    condition of problem 6.1 (a) is unchanged: s'_max = 2 / (1 - tau1 + tau2), eq. (78), and
    A = 2 tau1 / (1 - tau1 + tau2). The acceleration is continuous (zero where each blend meets
    the cruise and at rest), its peak pi / 2 times the trapezoid's, pi s'_max / (2 tau1).
    """

    name = "trapezoidal"

    def knots(self) -> np.ndarray:
        return np.array([0.0, 0.5 * self.tau1, self.tau1, self.tau2, 0.5 * (1.0 + self.tau2), 1.0])

    def inner_acceleration_steps(self) -> np.ndarray:
        return np.empty(0)

    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        t1, t2, v = self.tau1, self.tau2, self.peak_speed
        rising, falling = tau <= t1, tau >= t2
        # Blend phase angles: pi tau / tau1 on the rise, pi (1 - tau) / (1 - tau2) on the fall.
        up = np.pi * np.clip(tau / t1, 0.0, 1.0)
        down = np.pi * np.clip((1.0 - tau) / (1.0 - t2), 0.0, 1.0)
        A_up, A_down = t1 * v, (1.0 - t2) * v
        sigma = np.where(
            rising,
            0.5 * A_up * (up - np.sin(up)) / np.pi,
            np.where(falling, 1.0 - 0.5 * A_down * (down - np.sin(down)) / np.pi, 0.5 * A_up + v * (tau - t1)),
        )
        speed = np.where(rising, 0.5 * v * (1 - np.cos(up)), np.where(falling, 0.5 * v * (1 - np.cos(down)), v))
        acceleration = np.where(
            rising, 0.5 * v * np.pi / t1 * np.sin(up), np.where(falling, -0.5 * v * np.pi / (1 - t2) * np.sin(down), 0.0)
        )
        jerk = np.where(
            rising, 0.5 * v * (np.pi / t1) ** 2 * np.cos(up),
            np.where(falling, 0.5 * v * (np.pi / (1 - t2)) ** 2 * np.cos(down), 0.0),
        )
        return sigma, speed, acceleration, jerk


class CycloidalProfile(NormalizedProfile):
    """sigma = tau - sin(2 pi tau) / (2 pi) (Angeles eq. 6.38): zero speed and acceleration at
    both ends, peak acceleration 2 pi."""

    name = "cycloidal"

    def knots(self) -> np.ndarray:
        return np.array([0.0, 0.25, 0.5, 0.75, 1.0])

    def derivatives(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        angle = 2 * np.pi * tau
        return (
            tau - np.sin(angle) / (2 * np.pi),
            1 - np.cos(angle),
            2 * np.pi * np.sin(angle),
            4 * np.pi**2 * np.cos(angle),
        )


PROFILES: dict[str, type[NormalizedProfile]] = {"cubic": CubicProfile, "quintic": QuinticProfile, "trapezoidal": TrapezoidalProfile, "cycloidal": CycloidalProfile}
