"""A cell request planned: the arms built from the request (robots, base poses, spline paths,
scaled limits), timed together (``toptraj.planners.coordination``), and the answer: both
arms' samples on one clock, each as a ``trajectory_msgs/JointTrajectory``, the coordination
diagram and the time lost to coordination."""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.coordination import Cell, CellArm, Coordination, checked_rotation, coordinate
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.waypoints import make_path
from toptraj.service.formats import time_from_start
from toptraj.service.schemas.cells import CellArmRequest, CellRequest

#: Most samples per arm in an answer.
MAX_SAMPLES = 20_000
#: Points of the chosen curve in the answer's diagram.
CURVE_POINTS = 200


def _arm(index: int, request: CellArmRequest, deadline: Deadline) -> CellArm:
    robot = robots.load(request.robot)
    rotation = checked_rotation(request.base.rotation, f"arms[{index}].base.rotation")
    try:
        path = make_path(robot, WaypointPath(np.asarray(request.waypoints, dtype=float)), deadline)
    except InvalidRequest as error:
        raise InvalidRequest(f"arms[{index}]: {error}") from error
    limits = robot.limits.with_request(scales={"velocity": request.velocity_scale, "acceleration": request.acceleration_scale})
    return CellArm(robot, path, limits, rotation, np.asarray(request.base.position, dtype=float))


def _trajectory(arm: CellArm, t: np.ndarray, states) -> dict:
    q, qd, qdd = states
    stamps = time_from_start(t)
    return {
        "joint_names": list(arm.robot.joint_names),
        "points": [
            {"positions": q[k], "velocities": qd[k], "accelerations": qdd[k], "time_from_start": stamps[k]} for k in range(len(t))
        ],
    }


def _answer(cell: Cell, body: CellRequest, found: Coordination) -> dict:
    schedule = found.schedule
    count = int(np.ceil(schedule.duration / body.dt))
    if count > MAX_SAMPLES:
        raise InvalidRequest(
            f"the cell's motion lasts {schedule.duration:.4g} s: {count} samples of dt = {body.dt:g} s exceed {MAX_SAMPLES}; raise dt"
        )
    t = np.minimum(np.arange(count + 1) * body.dt, schedule.duration)
    states = schedule.states(cell, t)
    pick = np.linspace(0, len(found.curve) - 1, CURVE_POINTS).round().astype(int)
    clearance = found.clearance
    return {
        "duration": schedule.duration,
        "solo_durations": list(found.solo),
        "sequential_duration": sum(found.solo),
        "time_lost": found.time_lost,
        "schedule": schedule.kind,
        "t": t,
        "arms": [
            {"robot": arm.robot.name, "trajectory": _trajectory(arm, t, arm_states)} for arm, arm_states in zip(cell.arms, states)
        ],
        "min_distance": {
            "distance": clearance.distance,
            "t": clearance.t,
            "links": list(clearance.links),
            "guaranteed": clearance.bound,
        },
        "diagram": {"s": found.diagram.s, "blocked": found.diagram.blocked.astype(int), "curve": found.curve[pick]},
    }


def plan_cell(body: CellRequest, deadline: Deadline) -> dict:
    """The answer to a cell request (module docstring)."""
    arms = tuple(_arm(index, arm, deadline) for index, arm in enumerate(body.arms))
    cell = Cell(arms, body.clearance, tuple(body.constraints))
    return _answer(cell, body, coordinate(cell, deadline))
