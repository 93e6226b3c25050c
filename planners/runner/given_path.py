"""Timing a given path by a timing method: each stretch between corners (where the motion
stops) as its own problem, on its grid, between its boundary states, through the limit gate;
the stretches joined into one timing. Motion generators time the paths they find with it too
(``toptraj.planners.problem.methods.Execution.time_path``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.checks.gate import TimedStretch, gated
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.constraints.zones import on_stretch, with_edges
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.paths.stretch import Stretch, stretches
from toptraj.planners.problem.bounded import check_stretches_bounded
from toptraj.planners.problem.methods import Timed
from toptraj.planners.problem.path_checks import check_jerk_finite, check_path_within_limits, path_boundary, timing_grid
from toptraj.planners.runner.stretch_loads import over_every_stretch
from toptraj.planners.timing.base import Boundary, TimingMethod
from toptraj.planners.timing.segmented import SegmentedTiming

if TYPE_CHECKING:
    from toptraj.planners.execution.deadline import Deadline
    from toptraj.planners.paths.base import GeometricPath
    from toptraj.planners.problem.problem import BoundaryStates
    from toptraj.robots import JointLimits, Robot


def _stretch_boundary(boundary: Boundary, width: float, first: bool, last: bool) -> Boundary:
    """The boundary of one stretch in its own parameter (sigma-dot = s-dot / w): the path's
    boundary at the path's ends, rest at its corners."""
    def scaled(value):
        return None if value is None else value / width

    return Boundary(
        sd_start=boundary.sd_start / width if first else 0.0,
        sd_end=boundary.sd_end / width if last else 0.0,
        sdd_start=scaled(boundary.sdd_start) if first else None,
        sdd_end=scaled(boundary.sdd_end) if last else None,
    )


def _time_stretch(robot, stretch, method, grid_points, kinds, limits, boundary, duration, threshold, deadline, grid=None):
    if isinstance(stretch, Stretch):  # the zones in the stretch's own parameter
        limits = on_stretch(limits, stretch.start, stretch.width)
    s = timing_grid(stretch, grid_points, method, robot, grid)
    if limits.zones:
        s = with_edges(s, limits.zones, stretch.knots)
    deadline.progress(0.0, "constraints")
    constraints = build_path_constraints(stretch, robot, limits, kinds, s, deadline)
    if method.pointwise:
        start, width = (stretch.start, stretch.width) if isinstance(stretch, Stretch) else (0.0, 1.0)
        check_stretches_bounded(constraints, stretch, robot, limits, kinds, lambda sigma: start + width * sigma, method.kinds)
    deadline.check()
    timing, constraints, check = gated(
        robot, stretch, method, constraints, boundary, duration, kinds, limits, threshold, deadline.within(0.3, 1.0),
        grid_given=grid_points is not None,
    )
    return TimedStretch(stretch, timing, constraints, check)


def timed_path(
    robot: Robot, path: GeometricPath, method: TimingMethod, grid_points: int | None, states: BoundaryStates,
    duration: float | None, kinds: tuple[str, ...], limits: JointLimits, deadline: Deadline, threshold: float,
) -> Timed:
    """A given path timed by ``method`` on ``grid_points`` intervals (``None``: from the path),
    between the boundary ``states`` (``BoundaryStates``), in ``duration`` seconds (``None``: the
    shortest); each stretch between corners (where the motion stops) on its own, as its own
    rest-to-rest problem, and every one through the limit gate."""
    grid = path_grid(path, grid_points)
    check_path_within_limits(robot, path, grid)
    check_jerk_finite(path, kinds, method.name)
    boundary = path_boundary(path, states, duration, method)
    parts = stretches(path)
    widths = [getattr(part, "width", 1.0) for part in parts]
    counts = [None if grid_points is None else max(1, round(grid_points * w)) for w in widths]
    boundaries = [
        _stretch_boundary(boundary, w, k == 0, k == len(parts) - 1) if len(parts) > 1 else boundary
        for k, w in enumerate(widths)
    ]
    durations: list[float | None] = [None] * len(parts)
    if duration is not None and len(parts) > 1:
        shortest = [
            method.solve(build_path_constraints(part, robot, limits, kinds, path_grid(part, n), deadline), b, None, deadline).duration
            for part, n, b in zip(parts, counts, boundaries)
        ]
        durations = [duration * T / sum(shortest) for T in shortest]
    elif duration is not None:
        durations = [duration]
    shares = [deadline.within(k / len(parts), (k + 1) / len(parts)) for k in range(len(parts))]
    timed = []
    for part, n, b, T, share in zip(parts, counts, boundaries, durations, shares):
        try:
            timed.append(_time_stretch(robot, part, method, n, kinds, limits, b, T, threshold, share, grid if part is path else None))
        except InfeasiblePath as error:
            if not (isinstance(part, Stretch) and getattr(error, "joints", None)):
                raise
            raise over_every_stretch(error, part, [(other, path_grid(other, m)) for other, m in zip(parts, counts)], robot, limits, kinds, deadline) from error
    if len(timed) == 1:
        result = timed[0].timing
    else:
        ends = [part.end for part in parts if isinstance(part, Stretch)]
        assert len(ends) == len(parts)  # a path with corners comes apart into stretches
        edges = np.concatenate(([0.0], ends))
        result = SegmentedTiming(edges, tuple(item.timing for item in timed))
    return Timed(path, result, tuple(timed), method.name, cost=getattr(result, "cost", None))
