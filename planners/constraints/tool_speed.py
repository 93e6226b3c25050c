"""Tool-speed limits: the linear speed (m/s) and the angular speed (rad/s) of a frame of the
robot, the end effector unless the request names another (welding, gluing, painting).

The frame's twist along a timed path, in the frame's origin with world-aligned axes (Pinocchio's
``LOCAL_WORLD_ALIGNED``), is J(q) qd with qd = q' sd:

    v = J_v(q) q' sd,    w = J_w(q) q' sd,

linear in the path speed sd. A bound |v| <= v_max is therefore a first-order bound on sd,

    sd <= v_max / |J_v(q) q'|,

of the same form as a joint velocity limit (``PathConstraints.sd_max``), and every timing method
that reads ``sd_max`` holds it. The dense limit check computes |v| and |w| at its states from
the frame's Jacobian (``toptraj.planners.kinematics.frame_jacobians``).
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.errors import Conflicting, NotOneOf
from toptraj.planners.kinematics.frame_jacobians import frame_jacobians
from toptraj.robots import Robot, ToolSpeedLimit

#: Names of the tool limits, as ``peak_utilization`` and error messages show them.
TOOL_KINDS = ("tool_speed", "tool_angular_speed")


def tool_speed_limit(robot: Robot, frame: str | None, speed: float | None, angular_speed: float | None) -> ToolSpeedLimit | None:
    """The tool limit a request asks for, ``None`` when it names no speed.

    Raises:
        InvalidRequest: ``frame`` is not a frame of the robot (the message lists its frames), or
            a frame is named without a speed.
    """
    if speed is None and angular_speed is None:
        if frame is not None:
            raise Conflicting("tool.frame", frame, ("limits.tool_speed", "limits.tool_angular_speed"), rule="frame_without_speed")
        return None
    name = frame or robot.end_effector
    if not robot.model.existFrame(name):
        frames = tuple(item.name for item in robot.model.frames if item.name != "universe")
        raise NotOneOf("tool.frame", name, frames, rule="unknown_tool_frame", robot=robot.name)
    return ToolSpeedLimit(
        frame=name,
        frame_id=robot.frame_id(name),
        speed=np.inf if speed is None else float(speed),
        angular_speed=np.inf if angular_speed is None else float(angular_speed),
    )


def frame_twists(robot: Robot, frame_id: int, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """The frame's twist J(q) qd at each row of ``q``, ``qd`` (n, n_dof): shape (n, 6), linear
    velocity of its origin (m/s) then angular velocity (rad/s), in world-aligned axes."""
    jacobians = frame_jacobians(robot, frame_id, q)
    return np.einsum("nij,nj->ni", jacobians, np.atleast_2d(np.asarray(qd, dtype=float)))


def tool_speeds(robot: Robot, tool: ToolSpeedLimit, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """|v| (m/s) and |w| (rad/s) of the tool frame at each row of ``q``, ``qd``: shape (n, 2)."""
    twists = frame_twists(robot, tool.frame_id, q, qd)
    return np.column_stack([np.linalg.norm(twists[:, :3], axis=1), np.linalg.norm(twists[:, 3:], axis=1)])


def tool_speed_bound(
    robot: Robot, tool: ToolSpeedLimit, q: np.ndarray, dq: np.ndarray, speed: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The first-order bound the tool limit puts on sd along a path.

    Args:
        q, dq: The path and its s-derivative at n values of s, each (n, n_dof).
        speed: The largest linear speed (m/s) at each of the n points, (n,), where it varies
            along the path (``toptraj.planners.constraints.zones``); ``None``: ``tool.speed``.

    Returns:
        sd_max: Shape (n,), in 1/s (``inf`` where the frame does not move with s).
        kind: Shape (n,), the index in ``TOOL_KINDS`` of the bound that sets ``sd_max``.
    """
    per_unit = tool_speeds(robot, tool, q, dq)  # speeds per unit of sd
    with np.errstate(divide="ignore"):
        limit = np.broadcast_to(tool.bounds, per_unit.shape) if speed is None else np.column_stack(
            [speed, np.full(len(speed), tool.angular_speed)]
        )
        bounds = limit / per_unit
    kind = np.argmin(bounds, axis=1)
    return bounds[np.arange(len(bounds)), kind], kind
