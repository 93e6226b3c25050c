"""Joint waypoints as a request gives them: checked against the robot, repeats dropped, and
turned into a geometric path (spline, stop-and-go or blended; via points are timed and shaped together
in ``toptraj.planners.generators.via_points``, Cartesian lines in ``toptraj.planners.paths.cartesian``)."""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.errors import Conflicting, InvalidRequest, NotOneOf, OutOfRange, TooLarge, WrongLength
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths import GeometricPath, SplinePath, StopAndGoPath
from toptraj.planners.paths.blended import BlendedPath
from toptraj.planners.paths.cartesian import CartesianLine, cartesian_path
from toptraj.planners.paths.waypoints import COINCIDENT
from toptraj.planners.problem.ranges import COORDINATE, MAX_DEVIATION, MIN_SPACING, check
from toptraj.planners.problem.requests import DEFAULT_MAX_DEVIATION, WaypointPath
from toptraj.robots import Robot
from toptraj.robots.notes import Note

INTERPOLATIONS = {"spline": SplinePath, "linear": StopAndGoPath, "blend": BlendedPath}
MAX_WAYPOINTS = 1_000
#: Largest joint coordinate accepted (rad or m): a continuous joint may turn many times, not 1e300.
MAX_COORDINATE = COORDINATE.high


def checked_waypoints(robot: Robot, spec: WaypointPath) -> np.ndarray:
    """The waypoints of ``spec`` as an (n, n_dof) array, checked against the robot."""
    if spec.interpolation not in (*INTERPOLATIONS, "via"):
        raise NotOneOf("interpolation", spec.interpolation, sorted([*INTERPOLATIONS, "via"]))
    if spec.max_deviation is not None and spec.interpolation != "blend":
        raise Conflicting("max_deviation", spec.max_deviation, ("interpolation",), rule="deviation_needs_blend",
                          interpolation=spec.interpolation)
    waypoints = np.asarray(spec.waypoints, dtype=float) if np.ndim(spec.waypoints) == 2 else None
    if waypoints is None:
        raise InvalidRequest("waypoints", spec.waypoints, rule="not_joint_vectors")
    count, width = waypoints.shape
    if count < 2:
        raise InvalidRequest("waypoints", spec.waypoints, rule="too_few_waypoints", count=count)
    if count > MAX_WAYPOINTS:
        raise TooLarge("waypoints", spec.waypoints, count, MAX_WAYPOINTS, "waypoints", rule="too_many_waypoints")
    if width != robot.dof:
        raise WrongLength("waypoints[0]", waypoints[0], width, robot.dof, robot=robot.name, joint_names=robot.joint_names)
    bad = np.argwhere(~np.isfinite(waypoints) | (np.abs(waypoints) > MAX_COORDINATE))
    if bad.size:
        raise OutOfRange(f"waypoints[{bad[0][0]}][{bad[0][1]}]", waypoints[tuple(bad[0])], -MAX_COORDINATE, MAX_COORDINATE,
                         "rad or m", rule="coordinate_out_of_range")
    lower, upper = robot.limits.position_lower, robot.limits.position_upper
    outside = robot.outside_position_limits(waypoints)
    if outside is not None:
        index, joint = outside
        raise OutOfRange(f"waypoints[{index}][{joint}]", waypoints[index, joint], lower[joint], upper[joint],
                         rule="outside_joint_range", joint_name=robot.joint_names[joint], prismatic=robot.force_units[joint] == "N")
    return waypoints


def without_repeats(spec: WaypointPath, settable: bool = True) -> tuple[WaypointPath, tuple[Note, ...]]:
    """``spec`` without waypoints that repeat a neighbour (a recorded path that stands still for
    a while, or whose encoders jitter there), and a note saying which were dropped.

    A waypoint repeats when it lies within ``spec.min_spacing`` times the path's joint-space
    length (at least ``COINCIDENT``) of the waypoint kept before it; the first and the last
    waypoint are kept, a waypoint before the last that lies so near the last is dropped instead.
    A spline through two such waypoints turns within a stretch of s about spacing / length long:
    the arm nearly stops there, and the grid timings lose their conditioning (toppra and
    min_cost refused the Geering arm's recorded path with waypoints 1e-7 of its length apart).

    Args:
        spec: The waypoints, shape (n_waypoints, n_dof) in joint units.
        settable: Whether the caller can set ``min_spacing`` (the note then says that 0 keeps
            the waypoints).

    Raises:
        InvalidRequest: every waypoint is the same: there is nothing to move.
    """
    waypoints = np.asarray(spec.waypoints, dtype=float)
    if waypoints.ndim != 2 or len(waypoints) < 2 or not np.all(np.isfinite(waypoints)):
        return spec, ()
    check(spec.min_spacing, "min_spacing", MIN_SPACING)
    steps = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    length = float(steps.sum())
    spacing = max(spec.min_spacing * length, COINCIDENT)
    if np.all(steps > spacing):
        return spec, ()
    kept, merged = spread_waypoints(waypoints, spacing)
    if len(kept) < 2:
        raise InvalidRequest("waypoints", waypoints, rule="all_waypoints_coincide", count=len(waypoints), tolerance=COINCIDENT)
    dropped = np.setdiff1d(np.arange(len(waypoints)), kept)
    near = float(max(merged))
    shown = ", ".join(map(str, dropped[:10])) + (", ..." if dropped.size > 10 else "")
    note = Note(
        f"waypoints [{shown}] lie within {near:.2g} of a waypoint kept and were dropped ({dropped.size} in all)",
        "waypoints_dropped", field="waypoints", indices=tuple(int(i) for i in dropped), nearest=near,
        coincident=near <= COINCIDENT, share=spec.min_spacing, length=length, settable=settable,
    )
    return dataclasses.replace(spec, waypoints=waypoints[kept]), (note,)


def spread_waypoints(waypoints: np.ndarray, spacing: float) -> tuple[list[int], list[float]]:
    """(kept, merged): the indices of the waypoints (n, n_dof) kept, each farther than
    ``spacing`` from the one kept before it, the first and the last always kept (a kept waypoint
    within ``spacing`` of the last dropped in its place, the first excepted); and the distance of
    each dropped waypoint from the kept one it was dropped for."""
    kept, merged = [0], []
    for index in range(1, len(waypoints) - 1):
        distance = float(np.linalg.norm(waypoints[index] - waypoints[kept[-1]]))
        if distance > spacing:
            kept.append(index)
        else:
            merged.append(distance)
    last = len(waypoints) - 1
    while len(kept) > 1 and (distance := float(np.linalg.norm(waypoints[last] - waypoints[kept[-1]]))) <= spacing:
        kept.pop()
        merged.append(distance)
    distance = float(np.linalg.norm(waypoints[last] - waypoints[kept[-1]]))
    if distance > COINCIDENT:
        kept.append(last)
    else:
        merged.append(distance)
    return kept, merged


#: Distance (m, and rad of turn for poses) within which a Cartesian point repeats the one before it.
SAME_POINT = 1e-9


def without_repeated_points(line: CartesianLine) -> tuple[CartesianLine, tuple[Note, ...]]:
    """``line`` without the points that repeat the one before them (within ``SAME_POINT``), and a
    note saying which were dropped: a polyline stops at each of its points, so a repeat adds
    nothing. Malformed points are left for ``cartesian_path`` to refuse."""
    field = "positions" if line.poses is None else "poses"
    points = np.asarray(line.positions if line.poses is None else line.poses, dtype=float)
    if points.ndim != 2 or points.shape[1] not in (3, 7) or len(points) < 2 or not np.all(np.isfinite(points)):
        return line, ()
    same = np.linalg.norm(np.diff(points[:, :3], axis=0), axis=1) <= SAME_POINT
    if points.shape[1] == 7:  # the same rotation: unit q or -q, within SAME_POINT / 2 (half the angle)
        with np.errstate(divide="ignore", invalid="ignore"):
            unit = points[:, 3:] / np.linalg.norm(points[:, 3:], axis=1, keepdims=True)
        turn = np.minimum(np.linalg.norm(unit[1:] - unit[:-1], axis=1), np.linalg.norm(unit[1:] + unit[:-1], axis=1))
        same &= turn <= SAME_POINT / 2
    repeats = np.flatnonzero(same) + 1
    if repeats.size == 0:
        return line, ()
    note = Note(
        f"{field} {repeats.tolist()} repeat the point before them and were dropped", "points_dropped",
        field=field, indices=tuple(int(i) for i in repeats),
    )
    kept = np.delete(points, repeats, axis=0)
    return (dataclasses.replace(line, positions=kept) if field == "positions" else dataclasses.replace(line, poses=kept)), (note,)


CONTINUOUS = ("as_given", "shortest")


def continuous_turns(robot: Robot, spec: WaypointPath) -> tuple[WaypointPath, tuple[str, ...]]:
    """The waypoints of ``spec`` with the turns of its continuous joints as ``spec.continuous``
    asks, and notes for the caller.

    * ``"shortest"``: each waypoint of a continuous joint is moved by whole turns (2 pi) to lie
      within pi of the one before it, so the joint turns the short way (the first waypoint
      stays as given; the others may then read as equivalent angles, e.g. 6.0 as -0.283).
    * ``"as_given"``: the numbers are followed as they are; a note names each continuous joint
      that turns more than pi between two waypoints (the short way is shorter).
    """
    if spec.continuous not in CONTINUOUS:
        raise NotOneOf("continuous", spec.continuous, CONTINUOUS)
    waypoints = np.asarray(spec.waypoints, dtype=float)
    mask = np.asarray(robot.continuous, dtype=bool)
    if waypoints.ndim != 2 or waypoints.shape[1] != mask.size or not mask.any() or not np.all(np.isfinite(waypoints)):
        return spec, ()
    steps = np.diff(waypoints[:, mask], axis=0)
    if spec.continuous == "shortest":
        wrapped = steps - 2.0 * np.pi * np.round(steps / (2.0 * np.pi))
        if np.array_equal(wrapped, steps):
            return spec, ()
        shifted = waypoints.copy()
        shifted[:, mask] = waypoints[0, mask] + np.vstack([np.zeros(mask.sum()), np.cumsum(wrapped, axis=0)])
        moved = [robot.joint_names[j] for j, m in zip(np.flatnonzero(mask), (wrapped != steps).any(axis=0)) if m]
        note = Note(
            f"continuous joint(s) {', '.join(map(repr, moved))} turn the short way; their waypoints after "
            "the first are reached as equivalent angles (whole turns apart)",
            "turned_the_short_way", field="continuous", joints=tuple(moved),
        )
        return dataclasses.replace(spec, waypoints=shifted), (note,)
    index, column = np.nonzero(np.abs(steps) > np.pi)
    if index.size == 0:
        return spec, ()
    joints = [int(j) for j in np.flatnonzero(mask)]
    seen: dict[int, int] = {}
    for i, c in zip(index, column):
        seen.setdefault(joints[int(c)], int(i))
    notes = tuple(
        Note(
            f"continuous joint {robot.joint_names[j]!r} turns {steps[i][joints.index(j)]:+.4g} rad from "
            f"waypoint {i} to {i + 1}, more than pi: the other way round is shorter",
            "turns_the_long_way", field=f"waypoints[{i}]", joint_name=robot.joint_names[j],
            turn=float(steps[i][joints.index(j)]), index=i,
        )
        for j, i in seen.items()
    )
    return spec, notes


def make_path(robot: Robot, spec: WaypointPath | CartesianLine, deadline: Deadline = NO_DEADLINE) -> GeometricPath:
    """The geometric path of a Cartesian line, or of joint waypoints interpolated by spline or
    linear segments (via points are timed and shaped together, in ``via_points``)."""
    if isinstance(spec, CartesianLine):
        return cartesian_path(robot, spec, deadline)
    waypoints = checked_waypoints(robot, spec)
    if spec.interpolation == "blend":
        deviation = DEFAULT_MAX_DEVIATION if spec.max_deviation is None else spec.max_deviation
        check(deviation, "max_deviation", MAX_DEVIATION)
        return BlendedPath(waypoints, deviation)
    return INTERPOLATIONS[spec.interpolation](waypoints)
