"""The robot a request plans for: the catalog or uploaded robot carrying the request's
``payload`` and mounted by its ``mounting`` (``toptraj.robots.equipment``), and the words a
torque failure adds about that payload."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from toptraj import robots
from toptraj.planners.errors import InfeasiblePath
from toptraj.robots.equipment import equip
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest


def equipped_robot(request: TrajectoryRequest | CompareRequest) -> robots.Robot:
    """The request's robot carrying its ``payload`` and mounted by its ``mounting``
    (``toptraj.robots.equipment``; an upload's default payload when the request gives none)."""
    robot = robots.load(request.robot)
    if request.payload is None and request.mounting is None:
        return robot
    return equip(
        robot,
        None if request.payload is None else request.payload.payload(),
        None if request.mounting is None else request.mounting.mounting(),
    )


@contextmanager
def payload_named(robot: robots.Robot) -> Iterator[None]:
    """A torque limit a path cannot meet says that its torques include the robot's payload,
    and what to change."""
    try:
        yield
    except InfeasiblePath as error:
        payload = robot.payload
        if payload is None or getattr(error, "limit", None) != "torque":
            raise
        # a fact of the error, worded with it (``toptraj.service.problems.detail``)
        vars(error)["payload_carried"] = (payload.mass, payload.frame or robot.end_effector)
        raise
