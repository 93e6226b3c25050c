"""A limit asked far above the robot's own (degrees for radians, percent for a factor) is planned
under, as asked, and the answer's warnings say so with the slip that gives such a value."""

from __future__ import annotations

import pytest

from toptraj import robots
from toptraj.planners import LimitRequest, build_problem
from toptraj.planners.problem.raised_limits import RAISED_FACTOR
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

WAYPOINTS = [[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [1.0, -1.0, 1.2, 0.0, 0.6, 0.0]]


def _warnings(client, limits: dict) -> list[str]:
    answer = client.post("/v1/trajectories", json={"robot": "ur5", "path": {"waypoints": WAYPOINTS}, "timing": {"limits": limits}})
    assert answer.status_code == 200, answer.text
    return [warning for warning in answer.json()["warnings"] if "times its own limit" in warning]


def test_a_velocity_in_degrees_is_planned_under_and_named(client):
    (warning,) = _warnings(client, {"velocity": [180.0] * 6})
    assert warning.startswith(
        "timing.limits.velocity[0] = 180 puts the velocity limit of joint 'shoulder_pan_joint' at 180 rad/s, "
        "57.1 times its own limit of 3.15 rad/s: the motion is planned under it"
    )
    assert "radians, not degrees: 180 deg/s is 3.14 rad/s" in warning
    assert _warnings(client, {"velocity": [3.14] * 6}) == []  # the same in radians


def test_scales_in_percent_are_named_each(client):
    warnings = _warnings(client, {"velocity_scale": 80, "acceleration_scale": 80, "torque_scale": 0.8})
    assert [warning.split(" = ")[0] for warning in warnings] == ["timing.limits.velocity_scale", "timing.limits.acceleration_scale"]
    assert "a scale is a factor (timing.limits.velocity_scale = 0.8 for 80 %)" in warnings[0]
    assert _warnings(client, {"velocity_scale": 0.8, "acceleration_scale": 0.8}) == []


@pytest.mark.parametrize("factor, noted", [(RAISED_FACTOR * 0.99, False), (RAISED_FACTOR * 1.01, True)])
def test_the_note_starts_above_the_factor_and_names_the_joint_raised_most(factor, noted):
    """Torque overrides raise wrist_1_joint (28 N m) most: its ratio decides."""
    arm = robots.load("ur5")
    torque = [float(arm.limits.torque[0]), 150.0, 150.0, factor * 28.0, 28.0, 28.0]
    problem = build_problem(
        arm, WaypointPath(WAYPOINTS), PhasePlaneMethod(), limits=LimitRequest(kinds=("torque",), overrides={"torque": torque}),
    )
    notes = [note for note in problem.notes if getattr(note, "rule", None) == "limit_far_above_own"]
    assert bool(notes) == noted
    if noted:
        assert notes[0].facts["joint_name"] == "wrist_1_joint" and notes[0].facts["ratio"] == pytest.approx(factor)
