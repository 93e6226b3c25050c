"""``cubic``, ``quintic``, ``trapezoidal``, ``cycloidal``: classical time laws along a path
(lecture "Trajectory Planning"; Angeles ch. 6), for a given duration or the shortest one for
which every requested limit holds.

Along a stretch of path from s_a to s_b (span D) timed by a normalized profile sigma(tau) in T
seconds, with y = 1 / T:

    sd = D sigma' y,   sdd = D sigma'' y^2,   sddd = D sigma''' y^3,

so a limit row a sdd + b sd^2 + c + d sd in [lower, upper] becomes A y^2 + B y + c with
A = D (a sigma'' + b D sigma'^2) and B = d D sigma', the velocity bound reads
D sigma' y <= sd_max, and the jerk q' sddd + 3 q'' sd sdd + q''' sd^3 = J y^3. The shortest
duration is 1 / y* for the largest y* keeping every one of these within its limit at every
sample of tau: closed form per sample (a quadratic root, a cube root), no search. The place where
y* is decided is the binding limit.

A path with corners is timed segment by segment, stopping at each corner. Boundary speeds and
accelerations other than rest turn the segment into a polynomial in t that depends on T (the
lecture's cubic and quintic systems); its shortest duration is then found by bisection on T.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.held_load import holding_facts, static_load
from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.constraints.tool_speed import TOOL_KINDS
from toptraj.planners.errors import InfeasiblePath, InvalidRequest, NotServed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import AT_REST, Binding, Boundary, TimingMethod
from toptraj.planners.timing.laws.law_timing import LawSegment, LawTiming
from toptraj.planners.timing.laws.profiles import (
    CubicProfile,
    CycloidalProfile,
    NormalizedProfile,
    QuinticProfile,
    TrapezoidalProfile,
    cubic_coefficients,
    quintic_coefficients,
)

#: Keeps samples strictly inside a segment, so that a corner is seen from the segment's side.
_INSIDE = 1e-9


def _first_crossing(A, B, c, bound):
    """Smallest y > 0 with A y^2 + B y + c = bound (inf when none), elementwise."""
    with np.errstate(invalid="ignore", divide="ignore"):
        gap = bound - c
        disc = B * B + 4.0 * A * gap
        root = np.sqrt(np.maximum(disc, 0.0))
        quadratic = np.where(A != 0.0, np.minimum(
            np.where((-B + root) / (2 * A) > 0, (-B + root) / (2 * A), np.inf),
            np.where((-B - root) / (2 * A) > 0, (-B - root) / (2 * A), np.inf),
        ), np.inf)
        quadratic = np.where(disc >= 0.0, quadratic, np.inf)
        linear = np.where((A == 0.0) & (B != 0.0) & (gap / B > 0), gap / B, np.inf)
        return np.where(A != 0.0, quadratic, linear)


def _largest_inverse_duration(rows: PathConstraints, span, d1, d2, d3):
    """y* = 1 / T_min for a rest-to-rest profile sampled at the rows' points, and where it binds
    as (kind, row or joint index, sample index)."""
    candidates = []
    with np.errstate(divide="ignore", invalid="ignore"):
        velocity = np.where(span * d1 > 0, rows.sd_max / (span * d1), np.inf)
    candidates.append(("velocity", velocity[:, None]))
    if rows.a.shape[1]:
        A = span * (rows.a * d2[:, None] + rows.b * span * (d1**2)[:, None])
        B = rows.d * span * d1[:, None]
        y = np.minimum(_first_crossing(A, B, rows.c, rows.upper), _first_crossing(A, B, rows.c, rows.lower))
        candidates.append(("row", y))
    if rows.jerk is not None:
        dq, ddq, dddq, limit = rows.jerk
        J = span * (dq * d3[:, None] + 3 * ddq * span * (d1 * d2)[:, None] + dddq * span**2 * (d1**3)[:, None])
        with np.errstate(divide="ignore"):
            y = np.cbrt(limit / np.abs(J))
        candidates.append(("jerk", y))
    best, where = np.inf, None
    for kind, values in candidates:
        index = np.unravel_index(np.argmin(values), values.shape)
        if values[index] < best:
            best, where = float(values[index]), (kind, int(index[1]), int(index[0]))
    return best, where


class ClassicalMethod(TimingMethod):
    """A time law along the path; the shortest duration within the limits unless one is given.

    Args:
        profile: The normalized rest-to-rest profile.
        boundary_law: "cubic" or "quintic" when the law can also meet boundary speeds (and, for
            the quintic, accelerations); ``None`` for rest-to-rest only.
    """

    kinds = frozenset({"velocity", "acceleration", "torque", "jerk"})
    takes_duration = True
    pointwise = False  # one duration for the whole stretch: a limit anywhere on it bounds it (``law_unbounded`` else)

    def __init__(self, profile: NormalizedProfile, boundary_law: str | None = None):
        self.profile = profile
        self.name = profile.name
        self.boundary_law = boundary_law
        self.supporting_points = getattr(profile, "supporting_points", None)
        self.takes_acceleration_boundary = boundary_law == "quintic"
        # The samples' jerk (finite differences) is checked too where the law has no jumps.
        self.continuous_acceleration = not len(profile.acceleration_steps())

    def refuse_jerk_limit(self) -> None:
        """Refuse a jerk limit when the law's acceleration jumps (the cubic leaves rest with
        sigma''(0) = 6, the trapezoid switches between constant accelerations): its jerk is
        infinite there whatever the duration.

        Raises:
            InfeasiblePath: with ``limit = "jerk"`` and the first jump's tau as ``s`` (a law on
                one stretch; per stretch on a path with corners).
        """
        steps = self.profile.acceleration_steps()
        if not len(steps):
            return
        where = ", ".join(f"{tau:.4g}" for tau in steps)
        raise InfeasiblePath(
            f"the {self.profile.description}'s acceleration jumps at tau = {where} (as a fraction of each stretch's "
            "duration), so its jerk is infinite there and no duration holds a jerk limit",
            s=float(self.profile.derivatives(steps[:1])[0][0]),
            limit="jerk",
            rule="law_acceleration_steps",
            law=self.profile.description,
            steps=tuple(float(tau) for tau in steps),
        )

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> LawTiming:
        if constraints.jerk is not None:
            self.refuse_jerk_limit()
        moving = boundary.sd_start != 0.0 or boundary.sd_end != 0.0 or bool(boundary.sdd_start) or bool(boundary.sdd_end)
        if moving and self.boundary_law is None:
            raise NotServed("boundary", None, self.name, rule="law_from_rest_only", alternatives=("cubic", "quintic"))
        corners = constraints.s[1:-1][constraints.sd_max[1:-1] == 0.0]
        edges = np.concatenate(([0.0], corners, [1.0]))
        segments, bindings, minimal = [], [], []
        for k, (start, end) in enumerate(zip(edges[:-1], edges[1:])):
            deadline.check()
            ends = (
                boundary.sd_start if k == 0 else 0.0,
                boundary.sd_end if k == len(edges) - 2 else 0.0,
                (boundary.sdd_start or 0.0) if k == 0 else 0.0,
                (boundary.sdd_end or 0.0) if k == len(edges) - 2 else 0.0,
            )
            if any(ends):
                segment, binding = self._moving_segment(constraints, start, end, ends, deadline)
            else:
                segment, binding = self._rest_segment(constraints, start, end)
            segments.append(segment)
            bindings.append(binding)
            minimal.append(segment.duration)
        if duration is not None:
            factor = duration / sum(minimal)
            segments = [self._retimed(segment, segment.duration * factor, k, len(segments), boundary)
                        for k, segment in enumerate(segments)]
            return LawTiming(tuple(segments), binding=None, grid=constraints.s)
        slowest = int(np.argmax(minimal))
        return LawTiming(tuple(segments), binding=bindings[slowest], grid=constraints.s)

    def _samples(self, constraints, start, end, s):
        inside = np.clip(s, start + _INSIDE * (end - start), end - _INSIDE * (end - start))
        return constraints.evaluate(inside)

    def _rest_segment(self, constraints, start, end):
        """Shortest rest-to-rest segment: y* over 401 samples of tau, then twice over 33 samples
        between the neighbours of the binding sample (the extremum lies between them)."""
        span = end - start
        # The instants at which the law passes the constraints' grid points too: the grid holds
        # every waypoint and intervals between them, where a spline through nearly repeated
        # waypoints bends sharply over a stretch of s too short for uniform samples in time.
        grid = constraints.s[(constraints.s > start) & (constraints.s < end)]
        tau = np.union1d(np.union1d(np.linspace(0.0, 1.0, 401), self.profile.knots()), self.profile.tau_at((grid - start) / span))
        best = np.inf
        for _ in range(3):
            sigma, d1, d2, d3 = self.profile.derivatives(tau)
            rows = self._samples(constraints, start, end, start + span * sigma)
            y, where = _largest_inverse_duration(rows, span, d1, d2, d3)
            if where is None:
                raise InvalidRequest("constraints", None, rule="law_unbounded", law=self.name,
                                     detail=f"no requested limit bounds the {self.name} law's speed")
            if y <= best:
                best, (kind, index, sample), binding_rows = y, where, rows
                around = tau[max(where[2] - 1, 0)], tau[min(where[2] + 1, len(tau) - 1)]
            tau = np.linspace(*around, 33)
        y, rows = best, binding_rows
        if y <= 0.0:
            held, joint, _ = static_load(rows, sample)
            exceeded = kind if kind != "row" else rows.rows[index][0]
            raise InfeasiblePath(
                f"the {self.name} law cannot meet the limits at any duration: at s = {rows.s[sample]:.4f} "
                f"the {exceeded} limit is exceeded at rest",
                s=float(rows.s[sample]),
                joint=joint,
                limit=exceeded,
                held=held,
                **holding_facts(constraints),
            )
        return LawSegment(start, end, 1.0 / y, profile=self.profile), _binding(rows, kind, index, sample)

    def _polynomial(self, start, end, ends, T):
        sd0, sd1, sdd0, sdd1 = ends
        if self.boundary_law == "cubic":
            return cubic_coefficients(start, sd0, end, sd1, T)
        return quintic_coefficients(start, sd0, sdd0, end, sd1, sdd1, T)

    def _moving_segment(self, constraints, start, end, ends, deadline):
        """Shortest T for a boundary-conditioned polynomial: bisection on the limit check."""

        def worst(T):
            deadline.check()
            segment = LawSegment(start, end, T, coefficients=self._polynomial(start, end, ends, T))
            t = np.linspace(0.0, T, 401)
            s, sd, sdd, sddd = segment.states(t)
            if np.any(sd < -1e-9) or np.any(s < start - 1e-9) or np.any(s > end + 1e-9):
                return np.inf, segment, None
            rows = self._samples(constraints, start, end, s)
            ratio, where = _utilization(rows, sd, sdd, sddd)
            return ratio, segment, where

        rest_T = self._rest_segment(constraints, start, end)[0].duration
        high = rest_T
        for _ in range(60):
            if worst(high)[0] <= 1.0:
                break
            high *= 1.5
        else:
            raise InfeasiblePath(f"no {self.name} law meets the boundary velocities within the limits")
        low = high
        for _ in range(60):
            low /= 1.5
            if worst(low)[0] > 1.0:
                break
        for _ in range(50):
            middle = 0.5 * (low + high)
            if worst(middle)[0] <= 1.0:
                high = middle
            else:
                low = middle
        ratio, segment, (kind, index, sample, rows) = worst(high)
        return segment, _binding(rows, kind, index, sample)

    def _retimed(self, segment: LawSegment, T: float, k: int, count: int, boundary: Boundary) -> LawSegment:
        if segment.profile is not None:
            return LawSegment(segment.s_start, segment.s_end, T, profile=segment.profile)
        ends = (
            boundary.sd_start if k == 0 else 0.0,
            boundary.sd_end if k == count - 1 else 0.0,
            (boundary.sdd_start or 0.0) if k == 0 else 0.0,
            (boundary.sdd_end or 0.0) if k == count - 1 else 0.0,
        )
        return LawSegment(segment.s_start, segment.s_end, T, coefficients=self._polynomial(segment.s_start, segment.s_end, ends, T))


def _utilization(rows: PathConstraints, sd, sdd, sddd):
    """Largest value / limit over samples of one motion, and where it occurs."""
    ratios = []
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios.append(("velocity", (sd / rows.sd_max)[:, None]))
        if rows.a.shape[1]:
            value = rows.a * sdd[:, None] + rows.b * (sd**2)[:, None] + rows.c + rows.d * sd[:, None]
            ratios.append(("row", np.maximum(value / rows.upper, value / rows.lower)))
        if rows.jerk is not None:
            dq, ddq, dddq, limit = rows.jerk
            jerk = dq * sddd[:, None] + 3 * ddq * (sd * sdd)[:, None] + dddq * (sd**3)[:, None]
            ratios.append(("jerk", np.abs(jerk) / limit))
    best, where = -np.inf, None
    for kind, values in ratios:
        values = np.nan_to_num(values, nan=0.0)
        index = np.unravel_index(np.argmax(values), values.shape)
        if values[index] > best:
            best, where = float(values[index]), (kind, int(index[1]), int(index[0]), rows)
    return best, where


def _binding(rows: PathConstraints, kind: str, index: int, sample: int) -> Binding:
    if kind == "row":
        kind, joint = rows.rows[index]
    elif kind == "velocity" and rows.tool_bound is not None and rows.tool_bound[sample] >= 0:
        kind, joint = TOOL_KINDS[int(rows.tool_bound[sample])], None
    elif kind == "velocity":
        joint = int(rows.velocity_joint[sample]) if rows.velocity_joint is not None else -1
        joint = None if joint < 0 else joint
    else:
        joint = index
    return Binding(kind=kind, joint=None if joint is None else rows.joint_names[joint], s=float(rows.s[sample]))


def classical_methods(tau1: float = 1.0 / 3.0, tau2: float = 2.0 / 3.0) -> list[ClassicalMethod]:
    """The four time laws (trapezoidal with switching fractions ``tau1``, ``tau2``)."""
    return [
        ClassicalMethod(CubicProfile(), boundary_law="cubic"),
        ClassicalMethod(QuinticProfile(), boundary_law="quintic"),
        ClassicalMethod(TrapezoidalProfile(tau1, tau2)),
        ClassicalMethod(CycloidalProfile()),
    ]
