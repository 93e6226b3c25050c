"""The robot a request plans for: the catalog or uploaded robot carrying the request's
``payload`` and mounted by its ``mounting`` (``toptraj.robots.equipment``), and the words a
torque failure adds about that payload, and the payload and mounting an answer echoes."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from toptraj import robots
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.problem.gravity_notes import gravity_notes
from toptraj.robots.equipment import Mounting, Payload, equip
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
    and an unusual gravity of its mounting (``gravity_notes``), and what to change."""
    try:
        yield
    except InfeasiblePath as error:
        if getattr(error, "limit", None) != "torque":
            raise
        # facts of the error, worded with it (``toptraj.service.problems.detail``)
        payload = robot.payload
        if payload is not None:
            vars(error)["payload_carried"] = (payload.mass, payload.frame or robot.end_effector)
        unusual = gravity_notes(robot)
        if unusual:
            vars(error)["gravity_unusual"] = unusual[0]
        raise


#: Units of the echoed payload and mounting, stated in the answer beside them.
PAYLOAD_UNITS = {"mass": "kg", "center_of_mass": "m", "inertia": "kg m^2", "radius": "m"}
MOUNTING_UNITS = {"position": "m", "rotation": "1 (base axes to world axes, rows)", "gravity": "m/s^2"}


def payload_body(payload: Payload | None, end_effector: str) -> dict | None:
    """The payload a plan's torques include (``None``: none, or a mass of 0): mass, centre of mass in ``frame``,
    the 3x3 inertia about it in the frame's axes, the frame (the end effector by default), the
    radius of its collision sphere (0: none)."""
    if payload is None or (payload.mass == 0.0 and payload.radius == 0.0):
        return None
    return {
        "mass": payload.mass,
        "center_of_mass": list(payload.center_of_mass),
        "inertia": np.asarray(payload.inertia, dtype=float).reshape(3, 3).tolist(),
        "frame": payload.frame or end_effector,
        "radius": payload.radius,
        "units": PAYLOAD_UNITS,
    }


def mounting_body(mounting: Mounting | None, gravity: np.ndarray) -> dict | None:
    """The base pose a plan used (``None``: the model's own base, at the world's origin) and the
    ``gravity`` (3,) in the world its torques follow."""
    if mounting is None:
        return None
    return {
        "position": list(mounting.position),
        "rotation": np.asarray(mounting.rotation, dtype=float).reshape(3, 3).tolist(),
        "gravity": [float(value) for value in gravity],
        "units": MOUNTING_UNITS,
    }


def equipment_body(request: TrajectoryRequest | CompareRequest) -> dict:
    """The ``payload`` and ``mounting`` an answer to ``request`` was planned with, as
    ``equipped_robot`` applies them (an upload's default payload when the request gives none)."""
    robot = robots.load(request.robot)
    payload = robot.payload if request.payload is None else request.payload.payload()
    mounting = None if request.mounting is None else request.mounting.mounting()
    gravity = robot.model.gravity.linear if mounting is None or mounting.gravity is None else np.array(mounting.gravity)
    return {"payload": payload_body(payload, robot.end_effector), "mounting": mounting_body(mounting, gravity)}
