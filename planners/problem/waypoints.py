"""Joint waypoints as a request gives them: checked against the robot, repeats dropped, and
turned into a geometric path (spline, stop-and-go or blended; via points are timed and shaped together
in ``toptraj.planners.generators.via_points``, Cartesian lines in ``toptraj.planners.paths.cartesian``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from toptraj.planners.errors import Conflicting, InvalidRequest, NotOneOf, OutOfRange, TooLarge, WrongLength
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths import GeometricPath, SplinePath, StopAndGoPath
from toptraj.planners.paths.blended import BlendedPath
from toptraj.planners.paths.cartesian import CartesianLine, cartesian_path
from toptraj.planners.paths.waypoints import COINCIDENT
from toptraj.planners.problem.ranges import COORDINATE, MAX_DEVIATION, MIN_SPACING, check
from toptraj.planners.problem.requests import DEFAULT_MAX_DEVIATION, DEFAULT_MIN_SPACING, WaypointPath
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


#: Interpolations whose path turns between near waypoints (``DEFAULT_MIN_SPACING`` applies); a
#: ``"linear"`` path stops at each waypoint and via points pass each in its own segment, so only
#: exact repeats are dropped from them unless ``min_spacing`` is given.
TURNING = ("spline", "blend")


def without_repeats(spec: WaypointPath, settable: bool = True) -> tuple[WaypointPath, tuple[Note, ...]]:
    """``spec`` without waypoints that repeat a neighbour, and notes saying which were dropped:
    exact repeats (within ``COINCIDENT``: a recorded path that stands still for a while) and
    near ones (a standing arm's encoders jittering).

    A waypoint repeats nearly when it lies within the spacing, ``spec.min_spacing`` (default
    ``DEFAULT_MIN_SPACING`` on ``TURNING`` interpolations, else 0) times the path's joint-space
    length, of the waypoint kept before it; the first and the last waypoint are kept, a waypoint
    kept before the last that lies so near the last is dropped instead. A spline through two
    such waypoints turns within a stretch of s about spacing / length long: the arm nearly
    stops there, and the grid timings lose their conditioning (toppra and min_cost refused the
    Geering arm's recorded path with waypoints 1e-7 of its length apart). The waypoints kept
    carry their index in ``spec`` (``origin``), for notes that name waypoints.

    Args:
        spec: The waypoints, shape (n_waypoints, n_dof) in joint units, checked (``checked_waypoints``).
        settable: Whether the caller can set ``min_spacing`` (the note then says that 0 keeps
            the near waypoints).

    Raises:
        InvalidRequest: every waypoint is the same: there is nothing to move.
    """
    waypoints = np.asarray(spec.waypoints, dtype=float)
    if waypoints.ndim != 2 or len(waypoints) < 2 or not np.all(np.isfinite(waypoints)):
        return spec, ()
    share = spec.min_spacing
    if share is None:
        share = DEFAULT_MIN_SPACING if spec.interpolation in TURNING else 0.0
    check(share, "min_spacing", MIN_SPACING)
    steps = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    exact = np.flatnonzero(steps <= COINCIDENT) + 1
    if exact.size == len(waypoints) - 1:
        raise InvalidRequest("waypoints", waypoints, rule="all_waypoints_coincide", count=len(waypoints), tolerance=COINCIDENT)
    index = np.delete(np.arange(len(waypoints)), exact)
    length = float(steps.sum())
    kept = index[spread_waypoints(waypoints[index], share * length)]
    near = np.setdiff1d(index, kept)
    notes = []
    if exact.size:
        notes.append(_dropped(exact, "repeat the waypoint before them", coincident=True))
    if near.size:
        notes.append(_dropped(near, f"lie within {share:g} of the path's length of a waypoint kept", coincident=False,
                              nearest=nearest_kept(waypoints, kept, near), share=share, length=length, settable=settable))
    if spec.interpolation in TURNING:
        notes += sharp_near_pairs(waypoints[kept], kept, length, settable)
    if not notes:
        return spec, ()
    return dataclasses.replace(spec, waypoints=waypoints[kept], origin=tuple(int(i) for i in kept)), tuple(notes)


#: Two waypoints kept nearer than this share of the path's length, the path turning by more than
#: ``SHARP_TURN`` (rad) at either of them, are told of: the arm nearly stops between them (a
#: recording's jitter just beyond the spacing made the motion twice as long).
NEAR_PAIR = 1e-3
SHARP_TURN = np.pi / 3
#: Pairs named in the note, the first ones along the path.
PAIRS_SHOWN = 3


def sharp_near_pairs(waypoints: np.ndarray, origin: np.ndarray, length: float, settable: bool) -> list[Note]:
    """A note on the waypoints (n, n_dof, their indices as given ``origin``) nearer than
    ``NEAR_PAIR`` times ``length`` to the next, where the chords before or after turn by more
    than ``SHARP_TURN``: each pair's indices, distance and turn (degrees), and the
    ``min_spacing`` that drops one of each (the largest share rounded up, 1 % above)."""
    chords = np.diff(waypoints, axis=0)
    steps = np.linalg.norm(chords, axis=1)
    units = chords / steps[:, None]
    turns = np.arccos(np.clip(np.sum(units[1:] * units[:-1], axis=1), -1.0, 1.0))  # at each interior waypoint
    before = np.concatenate(([0.0], turns))
    after = np.concatenate((turns, [0.0]))
    sharp = np.flatnonzero((steps <= NEAR_PAIR * length) & (np.maximum(before, after) > SHARP_TURN))
    if sharp.size == 0:
        return []
    pairs = tuple((int(origin[k]), int(origin[k + 1]), float(steps[k]), float(np.degrees(max(before[k], after[k])))) for k in sharp)
    share = 1.01 * float(steps[sharp].max()) / length
    digit = 10.0 ** (math.floor(math.log10(share)) - 1)  # rounded up to two significant digits
    spacing = float(f"{math.ceil(share / digit) * digit:.2e}")  # 2 significant digits, never rounded to 0
    return [Note(
        f"waypoints {', '.join(f'{a} and {b}' for a, b, _, _ in pairs[:PAIRS_SHOWN])} lie nearer than {NEAR_PAIR:g} of the "
        "path's length and the path turns sharply there: the arm nearly stops between them",
        "sharp_near_pairs", field="waypoints", pairs=pairs, shown=PAIRS_SHOWN, length=length, spacing=spacing,
        settable=settable,
    )]


def _dropped(indices: np.ndarray, words: str, **facts) -> Note:
    shown = ", ".join(map(str, indices[:10])) + (", ..." if indices.size > 10 else "")
    return Note(f"waypoints [{shown}] {words} and were dropped ({indices.size} in all)", "waypoints_dropped",
                field="waypoints", indices=tuple(int(i) for i in indices), **facts)


def spread_waypoints(waypoints: np.ndarray, spacing: float) -> np.ndarray:
    """The indices of the waypoints (n, n_dof) kept, each farther than ``spacing`` from the one
    kept before it; the first and the last are kept, a kept waypoint within ``spacing`` of the
    last dropped in its place (the first excepted)."""
    steps = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    if np.all(steps > spacing):
        return np.arange(len(waypoints))
    kept = [0]
    for index in range(1, len(waypoints) - 1):
        if np.linalg.norm(waypoints[index] - waypoints[kept[-1]]) > spacing:
            kept.append(index)
    last = len(waypoints) - 1
    while len(kept) > 1 and np.linalg.norm(waypoints[last] - waypoints[kept[-1]]) <= spacing:
        kept.pop()
    return np.array([*kept, last])


def nearest_kept(waypoints: np.ndarray, kept: np.ndarray, dropped: np.ndarray) -> float:
    """The largest distance of a dropped waypoint from the nearer of the two waypoints kept on
    either side of it (``kept`` and ``dropped`` ascending indices into ``waypoints`` (n, n_dof))."""
    after = np.searchsorted(kept, dropped)
    before_distance = np.linalg.norm(waypoints[dropped] - waypoints[kept[after - 1]], axis=1)
    after_distance = np.linalg.norm(waypoints[dropped] - waypoints[kept[np.minimum(after, len(kept) - 1)]], axis=1)
    return float(np.minimum(before_distance, after_distance).max())


#: Distance (m, and rad of turn for poses) within which a Cartesian point repeats the one before it.
SAME_POINT = 1e-9


def repeated_points(line: CartesianLine) -> tuple[Note, ...]:
    """A note naming the points of ``line`` that repeat the one before them (within
    ``SAME_POINT``), which ``cartesian_path`` passes over: a polyline stops at each of its
    points, so a repeat adds nothing. Malformed points are left for ``cartesian_path`` to refuse."""
    field = "positions" if line.poses is None else "poses"
    points = np.asarray(line.positions if line.poses is None else line.poses, dtype=float)
    if points.ndim != 2 or points.shape[1] not in (3, 7) or len(points) < 2 or not np.all(np.isfinite(points)):
        return ()
    same = np.linalg.norm(np.diff(points[:, :3], axis=0), axis=1) <= SAME_POINT
    if points.shape[1] == 7:  # the same rotation: unit q or -q, within SAME_POINT / 2 (half the angle)
        with np.errstate(divide="ignore", invalid="ignore"):
            unit = points[:, 3:] / np.linalg.norm(points[:, 3:], axis=1, keepdims=True)
        turn = np.minimum(np.linalg.norm(unit[1:] - unit[:-1], axis=1), np.linalg.norm(unit[1:] + unit[:-1], axis=1))
        same &= turn <= SAME_POINT / 2
    repeats = np.flatnonzero(same) + 1
    if repeats.size == 0:
        return ()
    return (Note(f"{field} {repeats.tolist()} repeat the point before them and are passed over", "points_dropped",
                 field=field, indices=tuple(int(i) for i in repeats)),)


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
