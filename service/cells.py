"""A cell request planned: the arms built from the request (robots mounted by their base poses
and carrying their payloads, ``toptraj.robots.equipment``; spline paths; scaled limits), timed
together (``toptraj.planners.coordination``), and the answer in the format asked
(``toptraj.service.cell_answers``)."""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.coordination import Cell, CellArm, coordinate
from toptraj.planners.errors import InvalidRequest, WrongLength
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.problem.gravity_notes import gravity_notes
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.waypoints import make_path, without_repeats
from toptraj.robots.equipment import InvalidEquipment, equip, mounting
from toptraj.robots.errors import UnknownRobot
from toptraj.service.cell_answers import cell_body
from toptraj.service.formats import exact_period_for
from toptraj.service.problems import detail, note_text
from toptraj.service.schemas.cells import CellArmRequest, CellRequest


def _robot(index: int, request: CellArmRequest, gravity) -> robots.Robot:
    """The arm's robot mounted by its base pose under ``gravity`` and carrying its payload."""
    try:
        robot = robots.load(request.robot)
    except UnknownRobot as error:  # the same error, with the field that names the robot
        vars(error)["field"] = f"arms[{index}].robot"
        raise
    base = request.base
    try:
        payload = None if request.payload is None else request.payload.payload()
        return equip(robot, payload, mounting(base.position, base.rotation, base.orientation, gravity=gravity))
    except InvalidEquipment as error:
        where = "payload" if error.field in ("mass", "center_of_mass", "inertia", "frame") else "base"
        raise InvalidRequest(f"arms[{index}].{where}", detail=f"arms[{index}].{where}: {error.detail}") from error


def _in_arm(index: int, error: InvalidRequest) -> InvalidRequest:
    """``error`` of an arm's waypoints in the service's words (``problems.detail``), its fields
    named within the arm (``arms[i].waypoints``)."""
    text = detail(error).replace("path.waypoints", f"arms[{index}].waypoints")
    if f"arms[{index}]" not in text:
        text = f"arms[{index}]: {text}"
    return InvalidRequest(f"arms[{index}].waypoints", detail=text)


def _arm(index: int, request: CellArmRequest, gravity, deadline: Deadline, warnings: list[str]) -> CellArm:
    """Arm ``index`` of the cell, its waypoints that repeat the one before them dropped (a
    warning added to ``warnings``, as a trajectory's answer says it)."""
    robot = _robot(index, request, gravity)
    try:
        for row, waypoint in enumerate(request.waypoints):  # rows of other lengths make no array
            if len(waypoint) != robot.dof:
                raise WrongLength(f"waypoints[{row}]", waypoint, len(waypoint), robot.dof, robot=robot.name, joint_names=robot.joint_names)
        try:
            motion, dropped = without_repeats(WaypointPath(np.asarray(request.waypoints, dtype=float)), settable=False)
        except InvalidRequest as error:
            if getattr(error, "rule", None) != "all_waypoints_coincide":
                raise
            raise InvalidRequest(
                f"arms[{index}].waypoints", detail=(
                    f"arms[{index}] does not move: its {len(request.waypoints)} waypoints coincide. A cell times arms that "
                    f"move and keeps them apart from each other, not from an arm standing still: leave arms[{index}] out, "
                    "or give it a waypoint that differs from the first"
                ),
            ) from error
        warnings += [note_text(note).replace("path.waypoints", f"arms[{index}].waypoints") for note in dropped]
        path = make_path(robot, motion, deadline)
    except InvalidRequest as error:
        if error.field.startswith(f"arms[{index}]"):
            raise
        raise _in_arm(index, error) from error
    scales: dict[str, float | None] = {
        "velocity": request.velocity_scale,
        "acceleration": request.acceleration_scale,
        "torque": request.torque_scale,
    }
    return CellArm(robot, path, robot.limits.with_request(scales=scales))


def plan_cell(body: CellRequest, deadline: Deadline, format_: str | None = None) -> dict:
    """The answer to a cell request in ``format_`` (default the request's; ``csv``: the
    ``samples`` body that ``cell_answers.csv_bytes`` writes)."""
    warnings: list[str] = []
    arms = tuple(_arm(index, arm, body.gravity, deadline, warnings) for index, arm in enumerate(body.arms))
    # The cell's gravity, unusual as a trajectory's mounting.gravity is noted, in the cell's field.
    warnings[:0] = [note_text(note).replace("mounting.gravity", "gravity").replace("mounting.orientation", "an arm's base.orientation")
                    for note in gravity_notes(arms[0].robot)]
    cell = Cell(arms, body.clearance, tuple(body.constraints))
    format_ = format_ or body.format
    exact = exact_period_for(format_, body.exact_period)
    return cell_body(cell, coordinate(cell, deadline), body.dt, format_, exact, warnings)
