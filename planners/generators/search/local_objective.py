"""The objective J(P) of the local optimization (``toptraj.planners.generators.search.local``,
Jeong & Lee §2.6): the midpoint time-optimal duration along the clamped cubic B-spline of the
control points P plus the weighted distance and joint-range penalties.

Two ways to one number. The reference path builds the spline (``BSplinePath``), its
constraints (``build_path_constraints``) and times them (``midpoint_duration``), and takes the
distances with ``free_distances``. The fused path (``objective_kernels.objective_value``) does
the same arithmetic in one compiled call from basis weights computed once per round (the
knots change only between rounds): on the Geering arm an evaluation costs about a third of
the reference's, whose time went into building those objects, and answers the same J to
rounding. It serves every arm with a kinematic chain (``Robot.chain``) and capsule tables,
under velocity, acceleration and torque limits without zones or a tool-speed limit; the
others take the reference path.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from toptraj.planners.constraints.admissible_kernels import NOTHING_BEFORE, NOTHING_KEPT
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.generators.search.distance_kernels import obstacle_row
from toptraj.planners.generators.search.free_space import chain_tables, free_distances, joint_reaches
from toptraj.planners.generators.search.objective_kernels import basis_weights, objective_value
from toptraj.planners.paths.bspline import BSplinePath
from toptraj.planners.timing.phase_plane.method import BOUNDARY_SLACK, SLACK, midpoint_duration

if TYPE_CHECKING:
    from toptraj.planners.collision.obstacles import Obstacle
    from toptraj.planners.execution.deadline import Deadline
    from toptraj.planners.generators.search.local_outcome import LocalSettings
    from toptraj.robots import JointLimits, Robot

#: The objective of a path no timing can follow (s): above any duration served.
INFEASIBLE = 1e6
#: The constraint kinds the fused objective computes.
FUSED_KINDS = frozenset({"velocity", "acceleration", "torque"})


class AllowanceSpent(Exception):
    """The local optimization's own time allowance is spent: the round ends with its best point."""


class Objective:
    """J(P) on the interior control points x (flattened (k - 2) n_dof), counting its
    evaluations and checking the deadline at each. ``interior`` (the interior knots) is set
    before each round; ``fused`` says whether evaluations take the compiled path."""

    def __init__(
        self, robot: Robot, limits: JointLimits, kinds: tuple[str, ...], start: ArrayLike, goal: ArrayLike,
        obstacles: Iterable[Obstacle], clearance: float, settings: LocalSettings, deadline: Deadline,
    ) -> None:
        self.robot, self.limits, self.kinds = robot, limits, kinds
        self.start, self.goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
        self.obstacles, self.clearance, self.settings = list(obstacles), clearance, settings
        self.deadline = deadline
        self.grid = np.linspace(0.0, 1.0, settings.grid_intervals + 1)
        self.samples = np.linspace(0.0, 1.0, settings.obstacle_samples + 1)
        self.reach = joint_reaches(robot)
        lower, upper = limits.position_lower, limits.position_upper
        self.ranged = np.isfinite(lower) | np.isfinite(upper)
        self.evaluations = 0
        self._interior = np.empty(0)
        self._weights: tuple | None = None  # ``basis_weights`` of ``interior``
        self.stop_at = np.inf  # time.monotonic() beyond which a round ends early
        self.best: tuple[float, np.ndarray | None] = (np.inf, None)  # (objective, x) of the round under way
        self._fixed = self._fused_arguments()
        self.fused = self._fixed is not None

    @property
    def interior(self) -> np.ndarray:
        return self._interior

    @interior.setter
    def interior(self, knots: np.ndarray) -> None:
        knots = np.asarray(knots, dtype=float)
        if not np.array_equal(knots, self._interior):
            self._interior, self._weights = knots, None

    def round_begins(self) -> None:
        self.best = (np.inf, None)

    def path(self, x: np.ndarray) -> BSplinePath:
        inner = x.reshape(-1, len(self.start))
        return BSplinePath(np.vstack([self.start, inner, self.goal]), self.interior)

    def penalty(self, path: BSplinePath) -> float:
        """The weighted penalties (s) of ``path``: obstacles, self-collision (``free_distances``)
        and joint ranges (the reference path)."""
        settings, total = self.settings, 0.0
        q = path(self.samples)
        distance = free_distances(self.robot, q, self.obstacles, self.clearance, self.clearance + 0.1)
        if np.isfinite(distance).all():
            motion = np.abs(np.diff(q, axis=0)) @ self.reach
            inside = (distance[:-1] + distance[1:] - motion) / 2.0
            shortfall = np.maximum(self.clearance + settings.margin - np.minimum(inside, distance[:-1]), 0.0)
            total += settings.obstacle_weight * (shortfall.max() + shortfall.mean())
        if self.ranged.any():
            below = np.maximum(self.limits.position_lower - q, 0.0)
            above = np.maximum(q - self.limits.position_upper, 0.0)
            excursion = np.where(self.ranged, below + above, 0.0).max(axis=1)
            total += settings.range_weight * (excursion.max() + excursion.mean())
        return total

    def duration(self, path: BSplinePath) -> float:
        """Midpoint time-optimal duration (s) on the optimization grid; ``INFEASIBLE`` when no
        timing can follow the path (the reference path)."""
        constraints = build_path_constraints(path, self.robot, self.limits, self.kinds, self.grid)
        try:
            return midpoint_duration(constraints)
        except InfeasiblePath:
            return INFEASIBLE

    def reference(self, x: np.ndarray) -> float:
        """J at x by the reference path."""
        path = self.path(x)
        return self.duration(path) + self.penalty(path)

    def value(self, x: np.ndarray) -> float:
        """J at x: the fused path where it applies, else the reference path."""
        if self._fixed is None:
            return self.reference(x)
        return float(objective_value(np.ascontiguousarray(x, dtype=float), *self.fused_arguments()))

    def fused_arguments(self) -> tuple:
        """The arguments of ``objective_value`` after the interior control points, for the
        current knots (the fused path only)."""
        assert self._fixed is not None
        if self._weights is None:
            self._weights = basis_weights(self._interior)
        chain, limits, velocity_limited, distances, settings = self._fixed
        return (
            self.start, self.goal, self._weights, self.grid, self.samples, chain, limits, velocity_limited, distances, settings,
            INFEASIBLE, SLACK, BOUNDARY_SLACK, NOTHING_KEPT, NOTHING_BEFORE,
        )

    def __call__(self, x: np.ndarray) -> float:
        self.deadline.check()
        if time.monotonic() > self.stop_at:
            raise AllowanceSpent
        self.evaluations += 1
        value = self.value(x)
        if value < self.best[0]:
            self.best = (value, np.array(x, copy=True))
        return value

    def _fused_arguments(self) -> tuple | None:
        """The fixed arguments of ``objective_value`` (chain, limits, whether velocity is
        limited, distances, penalty settings), or ``None`` where the fused path does not apply."""
        robot, limits, kinds = self.robot, self.limits, self.kinds
        chain, tables = robot.chain, chain_tables(robot)
        if chain is None or tables is None or limits.zones or limits.tool is not None or not set(kinds) <= FUSED_KINDS:
            return None
        from toptraj.planners.collision.self_collision import self_pairs

        nothing = np.empty(0, dtype=np.int64)
        accelerated = np.flatnonzero(np.isfinite(limits.acceleration)) if "acceleration" in kinds else nothing
        torqued = np.flatnonzero(np.isfinite(limits.torque)) if "torque" in kinds else nothing
        fixed_limits = (
            np.asarray(robot.coulomb_friction, dtype=float), np.asarray(robot.viscous_friction, dtype=float),
            accelerated.astype(np.int64), np.asarray(limits.acceleration, dtype=float),
            torqued.astype(np.int64), np.asarray(limits.torque, dtype=float), np.asarray(limits.velocity, dtype=float),
        )
        chain_arrays = (
            chain.parent, chain.prismatic, chain.axis, chain.rotation, chain.translation, chain.coordinate,
            chain.mass, chain.lever, chain.inertia, chain.armature, chain.gravity,
        )
        rows = [obstacle_row(obstacle) for obstacle in self.obstacles]
        pairs = self_pairs(robot)
        distances = (
            tables[0], tables[1],
            np.array([kind for kind, _ in rows], dtype=np.int64), np.array([row for _, row in rows], dtype=float).reshape(-1, 19),
            (np.asarray(pairs.first, dtype=np.int64), np.asarray(pairs.second, dtype=np.int64), np.asarray(pairs.radius, dtype=float)),
            self.reach, (np.asarray(limits.position_lower, dtype=float), np.asarray(limits.position_upper, dtype=float), self.ranged),
            float(self.clearance),
        )
        settings = (float(self.settings.margin), float(self.settings.obstacle_weight), float(self.settings.range_weight))
        return chain_arrays, fixed_limits, "velocity" in kinds, distances, settings
