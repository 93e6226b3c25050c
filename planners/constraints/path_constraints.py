"""``PathConstraints``: every limit of a robot along a path, on a grid of s, computed once.

The one meeting point of dynamics and timing (DESIGN.md). With x = sd^2 (sd = ds/dt) and
u = sdd = d2s/dt2, the joint velocity, acceleration and torque along q(s) are

    qd   = q' sd
    qdd  = q' u + q'' x
    tau  = M(q) q' u + (M(q) q'' + C(q, q') q') x + g(q) + D q' sd + F sign(q')

(Jeong & Lee eq. (3.4b)/(3.6); Yamamoto et al. eq. (10)). Velocity limits give first-order
bounds sd <= sd_max(s); acceleration and torque limits give second-order rows
``a u + b x + c + d sd in [lower, upper]`` (d: viscous friction, zero for acceleration rows).
At a corner of the path (a kink, where q' jumps) the motion must stop, so sd_max = 0 there, and
the rows seen from the interval that ends there (``*_left``) differ from those of the interval
that starts there; so do they at a break (where q'' jumps: a line meeting a circular blend).
The torque coefficients come from the RNEA (``Robot.rnea_sets``): a = rnea(q, 0, q') - g,
b = rnea(q, q', q'') - g, c = g (+ Coulomb friction), so timing methods never see a robot; one
batched RNEA per chunk of grid points, then one compiled pass
(``toptraj.planners.constraints.assembly_kernels``) writes every row and the velocity bound.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from toptraj.planners.constraints.assembly_kernels import assemble_rows, velocity_bound
from toptraj.planners.constraints.linear_rows import LinearRows
from toptraj.planners.constraints.tool_speed import tool_speed_bound
from toptraj.planners.constraints.torque_interpolation import smooth_points
from toptraj.planners.constraints.zones import tool_speed_at, zone_factors, zoned_rows
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.paths.grid import on_points
from toptraj.robots import JointLimits, Robot

CONSTRAINT_KINDS = ("velocity", "acceleration", "torque", "jerk")


@dataclass(frozen=True)
class PathConstraints:
    """Limits along a path on a grid of N + 1 values of s.

    Attributes:
        s: Grid, shape (N + 1,), increasing from 0 to 1.
        sd_max: First-order bound on sd = ds/dt, shape (N + 1,), in 1/s; ``inf`` where none.
        a, b, c, d: Second-order rows ``a u + b x + c + d sd`` with u = sdd, x = sd^2, each of
            shape (N + 1, m); units of the limited quantity (rad/s^2 or N m). At a kink these
            hold the side of the interval that starts there.
        a_left, b_left, c_left, d_left: The same rows as seen from the interval that ends at each
            grid point; the very arrays ``a, b, c, d`` when the path has no kink or break.
        lower, upper: Bounds of the rows, shape (N + 1, m); ``-inf``/``inf`` where none.
        rows: (kind, joint index) of each of the m rows, kind "acceleration" or "torque".
        joint_names: Joint names, for messages.
        jerk: When jerk is limited, (dq, ddq, dddq, limit): the path's first three
            s-derivatives, each (N + 1, n_dof), and the jerk limit (n_dof,) in rad/s^3. The
            jerk dq sddd + 3 ddq sd sdd + dddq sd^3 involves sddd, so only the time laws,
            ruckig and jerk_limited read it.
        jerk_left: With ``jerk``, (dq, ddq, dddq) as seen from the interval that ends at each
            grid point (they differ from ``jerk``'s at the path's knots, where d3q/ds3 jumps).
        velocity_joint: Index of the joint whose velocity limit sets sd_max at each point
            (N + 1,), -1 where no velocity limit applies.
        tool_bound: Where a tool-speed limit (``toptraj.planners.constraints.tool_speed``) sets sd_max instead, the
            index of that limit in ``TOOL_KINDS`` (N + 1,), -1 elsewhere; ``None`` without one.
        knots: The s of the path's knots (where a derivative of q(s) jumps, so the rows are
            not smooth across them even where they are continuous); ``None`` when unknown.
        q: The path's points at the grid, (N + 1, n_dof); ``None`` when unknown.
        evaluate: Builds the same constraints at other values of s (for methods that refine).
        force_units: The unit of each joint's torque, "N m" or "N" (a prismatic joint), for
            messages; empty when unknown ("N m").
    """

    s: np.ndarray
    sd_max: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    a_left: np.ndarray
    b_left: np.ndarray
    c_left: np.ndarray
    d_left: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    rows: tuple[tuple[str, int], ...]
    joint_names: tuple[str, ...]
    jerk: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
    jerk_left: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    velocity_joint: np.ndarray | None = None
    tool_bound: np.ndarray | None = None
    knots: np.ndarray | None = None
    q: np.ndarray | None = None
    evaluate: Callable[..., PathConstraints] | None = field(default=None, repr=False, compare=False)
    force_units: tuple[str, ...] = ()

    def force_unit(self, joint: int) -> str:
        """The unit of joint ``joint``'s torque: "N m", or "N" for a prismatic joint."""
        return self.force_units[joint] if joint < len(self.force_units) else "N m"

    @property
    def can_refine(self) -> bool:
        """Whether rows can be evaluated at new values of s (``with_points``)."""
        return self.evaluate is not None

    def with_points(self, extra_s: np.ndarray) -> PathConstraints:
        """These constraints on the grid refined by ``extra_s`` (values strictly inside grid
        intervals, never at a corner), evaluating the rows only at the new points (the same
        rows a build on the refined grid computes there)."""
        if self.evaluate is None:
            raise ValueError("these constraints cannot be evaluated at other points (refinable is False)")
        extra = self.evaluate(np.asarray(extra_s, dtype=float))
        order = np.concatenate([self.s, extra.s]).argsort(kind="stable")

        def merge(mine, theirs):
            # take gathers whole rows at once; indexing with [order] goes element by element.
            return np.concatenate([mine, theirs]).take(order, axis=0)

        jerk = jerk_left = None
        if self.jerk is not None:
            assert extra.jerk is not None  # evaluated with the same limits
            jerk = (*(merge(mine, theirs) for mine, theirs in zip(self.jerk[:3], extra.jerk[:3])), self.jerk[3])
            if self.jerk_left is not None:
                jerk_left = tuple(merge(mine, theirs) for mine, theirs in zip(self.jerk_left, extra.jerk[:3]))
        right = tuple(merge(mine, theirs) for mine, theirs in zip((self.a, self.b, self.c, self.d), (extra.a, extra.b, extra.c, extra.d)))
        # Without corners or breaks the rows seen from the left are the very same arrays.
        same = self.a_left is self.a and self.b_left is self.b and self.c_left is self.c and self.d_left is self.d
        left = right if same else tuple(
            merge(mine, theirs) for mine, theirs in zip((self.a_left, self.b_left, self.c_left, self.d_left), (extra.a, extra.b, extra.c, extra.d))
        )
        merged = dataclasses.replace(  # rows, joint_names, knots and evaluate stay
            self,
            s=merge(self.s, extra.s),
            sd_max=merge(self.sd_max, extra.sd_max),
            a=right[0], b=right[1], c=right[2], d=right[3],
            a_left=left[0], b_left=left[1], c_left=left[2], d_left=left[3],
            lower=merge(self.lower, extra.lower),
            upper=merge(self.upper, extra.upper),
            velocity_joint=None if self.velocity_joint is None else merge(self.velocity_joint, extra.velocity_joint),
            tool_bound=None if self.tool_bound is None else merge(self.tool_bound, extra.tool_bound),
            jerk=jerk,
            jerk_left=jerk_left,
            q=None if self.q is None or extra.q is None else merge(self.q, extra.q),
        )
        # Seeds the cached ``smooth``: the new points lie strictly inside intervals, where the rows
        # are the same from both sides, so they are smooth unless one is a knot off the grid.
        new = np.ones(len(extra.s), dtype=bool) if self.knots is None else ~on_points(extra.s, self.knots)
        merged.__dict__["smooth"] = merge(self.smooth, new)
        merged.__dict__["has_friction"] = self.has_friction or bool(extra.d.any())
        merged.smooth.setflags(write=False)
        return merged

    def time_scaled(self, kappa: float) -> PathConstraints:
        """The same limits in a scaled time: with x = kappa x' and u = kappa u' (time runs
        sqrt(kappa) times slower), the rows ``(kappa a) u' + (kappa b) x' + c + (sqrt(kappa) d) sd'``
        and the bound sd' <= sd_max / sqrt(kappa). A solver that works with absolute tolerances
        sees x' of order one when ``kappa`` is the typical x of the path (``speed_scale``)."""
        root = np.sqrt(kappa)
        return dataclasses.replace(
            self,
            sd_max=self.sd_max / root,
            a=self.a * kappa,
            b=self.b * kappa,
            d=self.d * root,
            a_left=self.a_left * kappa,
            b_left=self.b_left * kappa,
            d_left=self.d_left * root,
            jerk=None,
            jerk_left=None,
            evaluate=None,
        )

    @cached_property
    def smooth(self) -> np.ndarray:
        """(N + 1,): the grid points through which the rows are smooth, computed once
        (``toptraj.planners.constraints.torque_interpolation.smooth_points``), read-only."""
        smooth = smooth_points(self)
        smooth.setflags(write=False)
        return smooth

    @cached_property
    def has_friction(self) -> bool:
        """Whether any row has a term linear in sd (viscous joint friction), seen from either
        side of a grid point (computed once)."""
        return bool(self.d.any() or (self.d_left is not self.d and self.d_left.any()))

    def linearized(self, x_ref: np.ndarray, side: str = "right") -> LinearRows:
        """Rows linear in (u, x), a conservative inner approximation of these constraints.

        A viscous term d sd = d sqrt(x) is replaced by a bound that can only tighten the row:
        against the upper bound, d sqrt(x) <= d (x + x_ref) / (2 sqrt(x_ref)) for d > 0 (tangent to
        the concave sqrt at x_ref, exact there) and d sqrt(x) <= 0 for d < 0; mirrored against the
        lower bound. Without friction the rows are returned unchanged.

        Args:
            x_ref: Shape (N + 1,), the x at which the tangent is taken (a good guess of the
                solution makes the approximation exact where it matters), in 1/s^2.
            side: "right" for the rows ``a, b, c, d``, "left" for ``a_left, ...``.
        """
        if side == "left":
            a, b, c, d = self.a_left, self.b_left, self.c_left, self.d_left
        else:
            a, b, c, d = self.a, self.b, self.c, self.d
        if not self.has_friction:
            return LinearRows(a, b, c, self.lower, self.upper)
        root = np.sqrt(np.maximum(x_ref, 1e-6))[:, None]
        positive, negative = np.maximum(d, 0.0), np.minimum(d, 0.0)
        upper_rows = (b + positive / (2 * root), c + positive * root / 2)
        lower_rows = (b + negative / (2 * root), c + negative * root / 2)
        infinite = np.full_like(self.lower, np.inf)
        return LinearRows(
            a=np.concatenate([a, a], axis=1),
            b=np.concatenate([upper_rows[0], lower_rows[0]], axis=1),
            c=np.concatenate([upper_rows[1], lower_rows[1]], axis=1),
            lower=np.concatenate([-infinite, self.lower], axis=1),
            upper=np.concatenate([self.upper, infinite], axis=1),
        )

    def describe_row(self, row: int) -> str:
        """'torque of joint elbow_joint' for row ``row`` of these (or the linearized) rows."""
        kind, joint = self.rows[row % len(self.rows)]
        return f"{kind} of joint {self.joint_names[joint]!r}"


def _rnea_terms(robot: Robot, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> np.ndarray:
    """(3 n, n_dof): RNEA(q, 0, 0) = g, RNEA(q, 0, q') = M q' + g and RNEA(q, q', q'') =
    M q'' + C(q, q') q' + g at the n rows of ``q, dq, ddq``, in one batched call whose three
    sets share the joint placements (``Robot.rnea_sets``)."""
    velocities = np.zeros((3, *dq.shape))
    velocities[2] = dq
    accelerations = np.empty((3, *dq.shape))
    accelerations[0] = 0.0
    accelerations[1] = dq
    accelerations[2] = ddq
    return robot.rnea_sets(q, velocities, accelerations).reshape(-1, dq.shape[1])


#: Grid points whose torque rows are computed between two deadline checks (about 20 ms).
CHUNK_POINTS = 1024


def grid_rows(robot: Robot, limits: JointLimits, kinds: tuple[str, ...], q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, deadline: Deadline = NO_DEADLINE
) -> tuple[tuple[np.ndarray, ...], tuple[tuple[str, int], ...]]:
    """The second-order rows ``(a, b, c, d, lower, upper)`` at n points of a path (``q, dq,
    ddq``, each (n, n_dof)) and their (kind, joint) labels: each array (n, m), acceleration rows
    then torque rows, of the joints whose limit is finite (a row with an infinite limit
    constrains nothing). The torque rows take one batched RNEA per ``CHUNK_POINTS`` points, the
    deadline checked before each; ``toptraj.planners.constraints.assembly_kernels.assemble_rows`` writes them."""
    nothing = np.empty(0, dtype=np.intp)
    accelerated = np.flatnonzero(np.isfinite(limits.acceleration)) if "acceleration" in kinds else nothing
    torqued = np.flatnonzero(np.isfinite(limits.torque)) if "torque" in kinds else nothing
    rows = tuple(("acceleration", int(j)) for j in accelerated) + tuple(("torque", int(j)) for j in torqued)
    n = len(q)
    arrays = tuple(np.empty((n, len(rows))) for _ in range(6))
    if not rows:
        return arrays, rows
    no_torque = np.empty((0, dq.shape[1]))
    acceleration = np.asarray(limits.acceleration, dtype=float)
    torque = np.asarray(limits.torque, dtype=float)
    for start in range(0, n, CHUNK_POINTS):
        deadline.check()
        part = slice(start, start + CHUNK_POINTS)
        tau = _rnea_terms(robot, q[part], dq[part], ddq[part]) if torqued.size else no_torque
        assemble_rows(
            dq[part], ddq[part], tau, robot.coulomb_friction, robot.viscous_friction, accelerated, acceleration, torqued, torque,
            *(array[part] for array in arrays),
        )
    return arrays, rows


def speed_bound(limits: JointLimits, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sd_max = min_j v_j / |q'_j| (n,, 1/s; inf where no joint moves) at the points of ``dq``
    (n, n_dof), and the joint that sets it (-1 where none does)."""
    sd_max = np.empty(len(dq))
    binding = np.empty(len(dq), dtype=np.intp)
    velocity_bound(dq, np.asarray(limits.velocity, dtype=float), sd_max, binding)
    return sd_max, binding


def _second_order_rows(path, robot: Robot, limits: JointLimits, kinds, s: np.ndarray, side: str, deadline: Deadline):
    """The path's points at ``s`` and their rows (``grid_rows``)."""
    points = path.evaluate(s, side)
    arrays, rows = grid_rows(robot, limits, kinds, points.q, points.dq, points.ddq, deadline)
    return points, arrays, rows


def _points_at(s: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Indices of the grid points of ``s`` that equal one of ``values`` (sorted); none
    without values, the common case of a smooth path."""
    if len(values) == 0:
        return np.empty(0, dtype=np.intp)
    return np.flatnonzero(np.isin(s, values))


def _left_derivatives(path: GeometricPath, s: np.ndarray, points, third: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """dq, ddq and dddq at ``s`` from the left: the right-hand values (``points``, ``third``)
    except at the path's knots, where the path is evaluated from the left."""
    dq, ddq, dddq = points.dq.copy(), points.ddq.copy(), third.copy()
    at_knot = np.flatnonzero(np.isin(s, path.knots) & (s > 0.0))
    if at_knot.size:
        left = path.evaluate(s[at_knot], "left")
        dq[at_knot], ddq[at_knot] = left.dq, left.ddq
        dddq[at_knot] = path.third_derivative(s[at_knot], "left")
    return dq, ddq, dddq


def _left_rows(path, robot: Robot, limits: JointLimits, kinds: tuple[str, ...], s: np.ndarray, right, deadline: Deadline):
    """The rows (a, b, c, d) seen from the interval that ends at each point: ``right``'s, but at
    a corner or a break of the curvature, where the left-hand derivatives differ."""
    a, b, c, d = right
    kink_index = _points_at(s, np.concatenate([path.kinks, path.breaks]))
    if not kink_index.size:
        return a, b, c, d
    _, (a_k, b_k, c_k, d_k, _, _), _ = _second_order_rows(path, robot, limits, kinds, s[kink_index], "left", deadline)
    a_left, b_left, c_left, d_left = a.copy(), b.copy(), c.copy(), d.copy()
    a_left[kink_index], b_left[kink_index] = a_k, b_k
    c_left[kink_index], d_left[kink_index] = c_k, d_k
    return a_left, b_left, c_left, d_left


def build_path_constraints(
    path: GeometricPath,
    robot: Robot,
    limits: JointLimits,
    kinds: tuple[str, ...],
    s: np.ndarray,
    deadline: Deadline = NO_DEADLINE,
) -> PathConstraints:
    """Evaluate the requested ``kinds`` of limits (subset of velocity, acceleration, torque)
    along ``path`` at the grid ``s`` (which must hold the path's kinks); a tool-speed limit
    (``limits.tool``) joins the first-order bound sd_max. Where ``limits.zones`` cover a point,
    its limits are theirs (``toptraj.planners.constraints.zones``)."""
    points, (a, b, c, d, lower, upper), rows = _second_order_rows(path, robot, limits, kinds, s, "right", deadline)
    deadline.check()
    factors = zone_factors(limits.zones, s) if limits.zones else None
    if factors is not None:
        lower, upper = zoned_rows(rows, lower, upper, factors)
    if "velocity" in kinds:
        sd_max, velocity_joint = speed_bound(limits, points.dq)
        sd_max = sd_max if factors is None else sd_max * factors.velocity
    else:
        sd_max, velocity_joint = np.full(len(s), np.inf), np.full(len(s), -1)
    tool_bound = None
    if limits.tool is not None:
        deadline.check()
        speed = None if factors is None else tool_speed_at(limits, s, factors)
        tool_sd_max, tool_kind = tool_speed_bound(robot, limits.tool, points.q, points.dq, speed)
        tool_bound = np.where(tool_sd_max < sd_max, tool_kind, -1)
        sd_max = np.minimum(sd_max, tool_sd_max)
    sd_max[_points_at(s, path.kinks)] = 0.0
    a_left, b_left, c_left, d_left = _left_rows(path, robot, limits, kinds, s, (a, b, c, d), deadline)
    third = path.third_derivative(s) if "jerk" in kinds else None
    return PathConstraints(
        s=s,
        sd_max=sd_max,
        a=a,
        b=b,
        c=c,
        d=d,
        a_left=a_left,
        b_left=b_left,
        c_left=c_left,
        d_left=d_left,
        lower=lower,
        upper=upper,
        rows=rows,
        joint_names=robot.joint_names,
        jerk=None if third is None else (points.dq, points.ddq, third, limits.jerk),
        jerk_left=None if third is None else _left_derivatives(path, s, points, third),
        velocity_joint=velocity_joint,
        tool_bound=tool_bound,
        knots=np.asarray(path.knots, dtype=float),
        q=points.q,
        evaluate=lambda extra_s: build_path_constraints(path, robot, limits, kinds, extra_s, deadline),
        force_units=robot.force_units,
    )
