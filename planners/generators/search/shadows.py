"""Obstacle shadows of a planar arm (Jeong & Lee section 2.2): the configuration-space obstacles
CO(b) = {y | R(y) meets b} (eq. 2.4) on a grid of joint space, and their images under the
forward kinematics of the tip, one per inverse-kinematic branch B_i (eq. 2.5):

    OS(b)_i = {x | x = FK(y), y in CO(b) and B_i}.

For a two-link planar arm the branches are the elbow's two sides, sin(q2) >= 0 and sin(q2) < 0.
The tip positions are given in the arm's plane (two coordinates), for the web page's picture.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.collision import Obstacle
from toptraj.planners.generators.search.free_space import joint_placements, point_distances
from toptraj.robots import Robot

#: Grid points per joint of the occupancy grid.
RESOLUTION = 48
#: Most tip points returned per branch.
MAX_TIP_POINTS = 1_500


def _plane(robot: Robot) -> tuple[np.ndarray, np.ndarray] | None:
    """Two unit vectors spanning the plane the arm moves in, when every joint turns about the
    same axis (a planar arm of revolute joints); None otherwise."""
    placed = joint_placements(robot, np.zeros((1, robot.dof)))
    if placed is None or robot.dof != 2:
        return None
    model = robot.model
    axes = []
    for j in range(1, model.njoints):
        name = model.joints[j].shortname()
        if not name.startswith(("JointModelR", "JointModelRevolute")):
            return None
        letter = name[-1]
        named = {"X": [1.0, 0, 0], "Y": [0, 1.0, 0], "Z": [0, 0, 1.0]}.get(letter)
        local = np.asarray(model.joints[j].extract().axis if named is None else named, dtype=float)
        axes.append(placed[0][0, j] @ local)
    axis = axes[0] / np.linalg.norm(axes[0])
    if any(abs(abs(a @ axis) / np.linalg.norm(a) - 1.0) > 1e-9 for a in axes):
        return None
    first = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    first /= np.linalg.norm(first)
    if abs(axis[2]) > 0.9:  # the usual horizontal arm: x and y of the world
        first = np.array([1.0, 0.0, 0.0])
    return first, np.cross(axis, first)


def obstacle_shadows(robot: Robot, obstacles: list[Obstacle], clearance: float, low: np.ndarray, high: np.ndarray) -> dict | None:
    """The occupancy grid of the configuration-space obstacles over [low, high] (n_dof,) and
    the obstacle shadows of the tip per branch, for a planar two-joint arm; None for others.

    Returns:
        ``{"joints", "q": [values of joint 1, values of joint 2] (rad), "occupied": rows per
        value of joint 1 of 0/1 per value of joint 2 (1: closer than the clearance), "shadows":
        [{"branch", "points": [[u, v], ...] (m, in the arm's plane)}]}``.
    """
    plane = _plane(robot)
    if plane is None or not obstacles:
        return None
    values = [np.linspace(low[j], high[j], RESOLUTION) for j in range(2)]
    grid = np.stack(np.meshgrid(*values, indexing="ij"), axis=-1).reshape(-1, 2)
    occupied = point_distances(robot, grid, list(obstacles), clearance) < clearance
    frame = robot.model.frames[robot.frame_id(robot.end_effector)]
    blocked = grid[occupied]
    shadows = []
    if blocked.size:
        placements = joint_placements(robot, blocked)
        assert placements is not None  # ``_plane`` found every joint of a kind it handles
        rotation, translation = placements
        joint = frame.parentJoint
        tip = np.einsum("kij,j->ki", rotation[:, joint], frame.placement.translation) + translation[:, joint]
        flat = np.column_stack([tip @ plane[0], tip @ plane[1]])
        upper = np.sin(blocked[:, 1]) >= 0.0
        names = robot.joint_names
        for label, mask in ((f"sin({names[1]}) >= 0", upper), (f"sin({names[1]}) < 0", ~upper)):
            points = flat[mask]
            if len(points) > MAX_TIP_POINTS:
                points = points[np.linspace(0, len(points) - 1, MAX_TIP_POINTS).astype(int)]
            shadows.append({"branch": label, "points": np.round(points, 5).tolist()})
    return {
        "joints": list(robot.joint_names),
        "q": [np.round(v, 6).tolist() for v in values],
        "occupied": occupied.reshape(RESOLUTION, RESOLUTION).astype(int).tolist(),
        "shadows": shadows,
    }
