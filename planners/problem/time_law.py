"""``TimeLaw``: a classical time law with its options, checked when it is made (the rules that
tie its own fields together), and the timing method it builds. The rules between the law and
the rest of the problem (a spline from rest only) are ``build_problem``'s."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.errors import InvalidRequest, NotOneOf, NotServed, OutOfRange
from toptraj.planners.problem.ranges import TRAPEZOID_FRACTION, check
from toptraj.planners.timing import METHODS
from toptraj.planners.timing.base import TimingMethod
from toptraj.planners.timing.laws.method import ClassicalMethod
from toptraj.planners.timing.laws.profiles import PROFILES, CycloidalBlendProfile, NormalizedProfile, TrapezoidalProfile
from toptraj.planners.timing.laws.splines import MAX_SUPPORTING_POINTS, MIN_SUPPORTING_POINTS, SplineProfile

#: Trapezoid ramps by name: constant acceleration (Angeles 6.1) or cycloidal blends (Angeles 6.3).
BLENDS: dict[str, type[TrapezoidalProfile]] = {"linear": TrapezoidalProfile, "cycloidal": CycloidalBlendProfile}


@dataclass(frozen=True)
class TimeLaw:
    """A classical time law (lecture "Trajectory Planning"; Angeles ch. 6) with its options.

    Attributes:
        name: ``cubic``, ``quintic``, ``trapezoidal`` or ``cycloidal``.
        fractions: (tau1, tau2), the trapezoidal law's ends of acceleration and of cruise as
            fractions of the duration, 0 < tau1 <= tau2 < 1.
        blend: ``"linear"`` (constant acceleration, Angeles 6.1) or ``"cycloidal"`` (cycloidal
            blends, Angeles 6.3) for the trapezoidal law's speed ramps.
        supporting_points: Approximate the law by the cubic spline through this many equally
            spaced points of it (Angeles 6.1 (c), ``toptraj.planners.timing.laws.splines``);
            ``None``: the law itself.

    Raises (when made):
        NotServed: a blend on a law other than the trapezoid, supporting points on a name that
            is no time law.
        InvalidRequest: tau1 > tau2, or fractions outside (0, 1); a spline that moves backwards.
        OutOfRange: a fraction or a count of supporting points outside its range.
    """

    name: str
    fractions: tuple[float, float] = (1.0 / 3.0, 2.0 / 3.0)
    blend: str = "linear"
    supporting_points: int | None = None

    def __post_init__(self) -> None:
        if self.blend != "linear" and self.name != "trapezoidal":
            raise NotServed("law.blend", self.blend, self.name, rule="blend_needs_trapezoidal", alternatives=("trapezoidal",))
        if self.supporting_points is not None and self.name not in PROFILES:
            raise NotServed("law.supporting_points", self.supporting_points, self.name, rule="needs_time_law",
                            alternatives=tuple(PROFILES))
        if self.name == "trapezoidal":
            tau1, tau2 = self.fractions
            if not (np.isfinite(tau1) and np.isfinite(tau2) and 0.0 < tau1 <= tau2 < 1.0):
                raise InvalidRequest("law.trapezoid", (tau1, tau2), rule="trapezoid_order")
            for name, value in (("tau1", tau1), ("tau2", tau2)):
                check(value, f"law.trapezoid.{name}", TRAPEZOID_FRACTION)
            if self.blend not in BLENDS:
                raise NotOneOf("law.blend", self.blend, list(BLENDS))
        points = self.supporting_points
        if points is not None and not (isinstance(points, int) and MIN_SUPPORTING_POINTS <= points <= MAX_SUPPORTING_POINTS):
            raise OutOfRange("law.supporting_points", points, MIN_SUPPORTING_POINTS, MAX_SUPPORTING_POINTS, rule="count_out_of_range")

    def profile(self) -> NormalizedProfile:
        """The normalized profile: the law (trapezoid fractions and blend), or its spline through
        ``supporting_points`` points."""
        profile = BLENDS[self.blend](*self.fractions) if self.name == "trapezoidal" else PROFILES[self.name]()
        if self.supporting_points is None:
            return profile
        try:
            return SplineProfile(profile, self.supporting_points)
        except ValueError as error:
            raise InvalidRequest("law.supporting_points", self.supporting_points, rule="law_spline_failed", reason=str(error)) from None

    def method(self) -> TimingMethod:
        """The timing method of the law: the catalog's own where no option differs from it."""
        if self.name == "trapezoidal" or self.supporting_points is not None:
            boundary_law = getattr(METHODS[self.name], "boundary_law", None) if self.supporting_points is None else None
            return ClassicalMethod(self.profile(), boundary_law=boundary_law)
        return METHODS[self.name]


