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


def _warnings(client, limits: dict, **timing) -> list[str]:
    body = {"robot": "ur5", "path": {"waypoints": WAYPOINTS}, "timing": {"limits": limits, **timing}}
    answer = client.post("/v1/trajectories", json=body)
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


def test_an_override_and_a_scale_are_named_together_with_the_slip_of_the_one_beyond(client):
    (warning,) = _warnings(client, {"velocity": [3.0] * 6, "velocity_scale": 80})
    assert warning.startswith("timing.limits.velocity[0] = 3 and timing.limits.velocity_scale = 80 put the velocity limit")
    assert "a scale is a factor (timing.limits.velocity_scale = 0.8 for 80 %)" in warning


def test_a_limit_not_held_is_noted_for_its_utilization(client):
    """Torque left out of the constraints is still reported in peak_utilization, against the
    limit asked."""
    (warning,) = _warnings(client, {"torque_scale": 100}, constraints=["velocity", "acceleration"])
    assert ": peak_utilization is measured against it. If that is not meant, a scale is a factor" in warning
    assert "planned under it" not in warning


def test_a_limit_of_the_services_default_rule_is_no_rating(client):
    """ur5's jerk limit (200 rad/s^3) comes from the default rule, not a datasheet: a jerk
    limit of 1,000 is no slip."""
    arm = robots.load("ur5")
    assert arm.limit_sources["jerk"][0].startswith("default")
    assert _warnings(client, {"jerk": [1000.0] * 6}, method="jerk_limited") == []


def test_a_prismatic_joint_is_spoken_of_in_metres(client):
    from tests.paths import DATA

    created = client.post("/v1/robots", json={"name": "lift_raised", "urdf": (DATA / "lift_rp.urdf").read_text()})
    assert created.status_code == 201, created.text
    lift = created.json()
    joint = lift["joint_names"].index("lift")
    velocity = [lift["limits"]["velocity"][j] * (20.0 if j == joint else 1.0) for j in range(len(lift["joint_names"]))]
    answer = client.post("/v1/trajectories", json={
        "robot": "lift_raised", "path": {"waypoints": [[0.0] * len(velocity), [0.1] * len(velocity)]},
        "timing": {"limits": {"velocity": velocity}},
    })
    assert answer.status_code == 200, answer.text
    (warning,) = [w for w in answer.json()["warnings"] if "times its own limit" in w]
    assert "m/s, 20 times its own limit of" in warning and "one per joint in the robot's joint order" in warning
    assert "degrees" not in warning
