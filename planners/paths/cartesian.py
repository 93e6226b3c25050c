"""Cartesian paths: straight lines of a frame (positions linear, orientation by slerp) turned
into a joint path by inverse kinematics (lecture "Trajectory Planning", Cartesian-space
trajectories: divide the line into small segments, solve the inverse kinematics at each point).

Each line is sampled every 2 mm and 1 degree at most, the damped-least-squares IK is seeded from
the start configuration and continued point to point, and a C2 spline through the joint
solutions is the joint path. The result is checked: the frame stays within
``POSITION_TOLERANCE`` of the line along the whole spline, and the IK meets every point. A line
that leaves the workspace, passes a singularity or needs a joint jump is refused with the place.
A polyline stops at each corner.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from toptraj.planners.errors import Conflicting, InvalidRequest, NotOneOf
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.kinematics.ik import frame_pose, solve_ik
from toptraj.planners.paths.base import GeometricPath
from toptraj.planners.paths.concatenated import ConcatenatedPath
from toptraj.planners.paths.waypoints import SplinePath
from toptraj.robots import Robot

STEP_LENGTH_M = 0.002
STEP_ANGLE_RAD = np.radians(1.0)
MIN_STEPS = 20
#: The joint path may deviate from the Cartesian line by this much (m).
POSITION_TOLERANCE = 1e-4
ROTATION_TOLERANCE = 1e-3
#: Smallest singular value of the task Jacobian (m/rad or rad/rad) accepted along the line.
SINGULAR_VALUE_FLOOR = 1e-3
#: Largest joint move between two consecutive IK points (rad or m).
MAX_JOINT_STEP = 0.25
#: Most IK points along one line (40 m at 2 mm): far beyond any arm's reach.
MAX_STEPS_PER_LINE = 20_000


@dataclass(frozen=True)
class CartesianLine:
    """A polyline of the frame ``frame`` (default: the robot's end effector) from the pose at
    joint configuration ``start`` through ``positions`` (n, 3) in m, or ``poses`` (n, 7) as
    x, y, z, qx, qy, qz, qw. A first point equal to the start pose may be given or omitted."""

    start: np.ndarray
    positions: np.ndarray | None = None
    poses: np.ndarray | None = None
    frame: str | None = None


def _targets(line: CartesianLine, start_pose: pin.SE3):
    if (line.positions is None) == (line.poses is None):
        raise Conflicting("positions", line.positions, ("positions", "poses"), rule="positions_or_poses")
    field = "positions" if line.poses is None else "poses"
    points = np.asarray(line.positions if line.poses is None else line.poses, dtype=float)
    width = 3 if line.poses is None else 7
    if points.ndim != 2 or points.shape[1] != width or len(points) == 0:
        raise InvalidRequest(field, points, rule="not_cartesian_rows", width=width)
    bad = np.argwhere(~np.isfinite(points))
    if bad.size:
        raise InvalidRequest(f"{field}[{bad[0][0]}][{bad[0][1]}]", float(points[tuple(bad[0])]), rule="not_finite_number")
    positions = points[:, :3]
    rotations = [None] * len(points)
    if width == 7:
        norms = np.linalg.norm(points[:, 3:], axis=1)
        if np.any(np.abs(norms - 1.0) > 1e-3):
            index = int(np.argmax(np.abs(norms - 1.0)))
            raise InvalidRequest(f"{field}[{index}]", points[index], rule="quaternion_not_unit", norm=float(norms[index]))
        rotations = [pin.Quaternion(w, x, y, z).normalized().toRotationMatrix() for x, y, z, w in points[:, 3:]]
    first_is_start = np.linalg.norm(positions[0] - start_pose.translation) < 1e-6 and (
        rotations[0] is None or np.linalg.norm(pin.log3(rotations[0] @ start_pose.rotation.T)) < 1e-6
    )
    offset = 1 if first_is_start else 0
    positions, rotations = positions[offset:], rotations[offset:]
    if len(positions) == 0:
        raise InvalidRequest(field, points, rule="only_the_start_pose")
    start_rotation = start_pose.rotation if width == 7 else None
    return field, offset, np.vstack([start_pose.translation, positions]), [start_rotation, *rotations]


def cartesian_path(robot: Robot, line: CartesianLine, deadline: Deadline = NO_DEADLINE) -> GeometricPath:
    """The joint path that moves the frame along ``line``.

    Raises:
        InvalidRequest: malformed points, a frame the robot lacks, a start outside the joint
            limits, a line that leaves the workspace, crosses a singularity or needs a joint jump.
        BudgetExceeded: ``deadline`` passed (checked at every point of the line).
    """
    frame = line.frame or robot.end_effector
    if not robot.model.existFrame(frame):
        frames = tuple(item.name for item in robot.model.frames if item.name != "universe")
        raise NotOneOf("frame", frame, frames, rule="unknown_frame", robot=robot.name)
    frame_id = robot.frame_id(frame)
    start = np.asarray(line.start, dtype=float)
    if start.shape != (robot.dof,) or not np.all(np.isfinite(start)):
        raise InvalidRequest("start", line.start, rule="not_finite_joint_values", expected=robot.dof)
    outside = robot.outside_position_limits(start)
    if outside is not None:
        column = outside[1]
        raise InvalidRequest(f"start[{column}]", float(start[column]), rule="outside_joint_limits", joint_name=robot.joint_names[column])
    field, offset, positions, rotations = _targets(line, frame_pose(robot, start, frame_id))
    pieces: list[GeometricPath] = []
    lengths: list[float] = []
    q = start
    for k in range(len(positions) - 1):
        span = np.linalg.norm(positions[k + 1] - positions[k])
        if span / STEP_LENGTH_M > MAX_STEPS_PER_LINE:
            raise InvalidRequest(f"{field}[{k + offset}]", positions[k + 1], rule="line_too_long", length=float(span), robot=robot.name)
        samples = _line_samples(positions[k], positions[k + 1], rotations[k], rotations[k + 1])
        if samples is None:  # a point repeated: the line stops there anyway (told by the problem's notes)
            continue
        solutions = [q]
        for fraction, (position, rotation) in samples:
            deadline.check()
            result = solve_ik(robot, solutions[-1], frame_id, position, rotation)
            where = {"index": k + offset, "fraction": fraction, "position": np.round(position, 4).tolist(), "robot": robot.name}
            if result.error > 1e-6:
                raise InvalidRequest(f"{field}[{k + offset}]", positions[k + 1], rule="point_out_of_reach", **where)
            if result.sigma_min < SINGULAR_VALUE_FLOOR:
                raise InvalidRequest(f"{field}[{k + offset}]", positions[k + 1], rule="line_crosses_singularity", **where)
            jump = np.abs(result.q - solutions[-1])
            if jump.max() > MAX_JOINT_STEP:
                joint = robot.joint_names[int(np.argmax(jump))]
                raise InvalidRequest(f"{field}[{k + offset}]", positions[k + 1], rule="joint_jump", jump=float(jump.max()),
                                     joint_name=joint, **where)
            solutions.append(result.q)
        joint_points = np.array(solutions)
        piece = SplinePath(joint_points)
        _check_deviation(robot, frame_id, piece, positions[k], positions[k + 1], field, k + offset, deadline)
        pieces.append(piece)
        lengths.append(float(np.sum(np.linalg.norm(np.diff(joint_points, axis=0), axis=1))))
        q = joint_points[-1]
    if not pieces:
        raise InvalidRequest(field, None, rule="only_the_start_pose")
    return ConcatenatedPath(pieces, np.array(lengths))


def _line_samples(p0, p1, r0, r1):
    """(fraction, (position, rotation)) at the sampling points of one line, start excluded."""
    length = np.linalg.norm(p1 - p0)
    angle = 0.0 if r0 is None else np.linalg.norm(pin.log3(r0.T @ r1))
    if length < 1e-9 and angle < 1e-9:
        return None
    count = max(MIN_STEPS, int(np.ceil(length / STEP_LENGTH_M)), int(np.ceil(angle / STEP_ANGLE_RAD)))
    samples = []
    for fraction in np.linspace(0.0, 1.0, count + 1)[1:]:
        rotation = None if r0 is None else r0 @ pin.exp3(fraction * pin.log3(r0.T @ r1))
        samples.append((fraction, (p0 + fraction * (p1 - p0), rotation)))
    return samples


def _check_deviation(robot, frame_id, piece, p0, p1, field, index, deadline):
    """The frame stays within POSITION_TOLERANCE of the straight line along the whole spline."""
    s = np.linspace(0.0, 1.0, 8 * len(piece.knots) + 1)
    direction = p1 - p0
    length = np.linalg.norm(direction)
    worst = 0.0
    for k, q in enumerate(piece(s)):
        if k % 64 == 0:
            deadline.check()
        offset = frame_pose(robot, q, frame_id).translation - p0
        if length > 0:
            along = np.clip(offset @ direction / length**2, 0.0, 1.0)
            offset = offset - along * direction
        worst = max(worst, float(np.linalg.norm(offset)))
    if worst > POSITION_TOLERANCE:
        raise InvalidRequest(f"{field}[{index}]", None, rule="joint_path_strays", deviation=worst, tolerance=POSITION_TOLERANCE)
