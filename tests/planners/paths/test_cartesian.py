"""Cartesian straight lines by inverse kinematics: the lecture's table, and lines via HTTP."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners.kinematics.ik import frame_pose, solve_ik

INCH = 0.0254
LECTURE_TABLE = np.array(
    [
        [9.0, 6.0, 10.0, 56.3, 27.2, 104.7],
        [8.4, 5.9, 9.8, 54.9, 25.4, 109.2],
        [7.8, 5.8, 9.6, 53.4, 23.8, 113.6],
        [7.2, 5.7, 9.4, 51.6, 22.4, 117.9],
        [6.6, 5.6, 9.2, 49.7, 21.2, 121.9],
        [6.0, 5.5, 9.0, 47.5, 20.1, 125.8],
        [5.4, 5.4, 8.8, 45.0, 19.3, 129.5],
        [4.8, 5.3, 8.6, 42.2, 18.7, 133.0],
        [4.2, 5.2, 8.4, 38.9, 18.4, 136.3],
        [3.6, 5.1, 8.2, 35.2, 18.5, 139.4],
        [3.0, 5.0, 8.0, 31.0, 18.9, 142.2],
    ]
)


def lecture_inverse_kinematics(point_in):
    """The lecture's printed inverse kinematics (inches, radians)."""
    px, py, pz = point_in
    t1 = np.arctan(px / py)
    c1 = np.cos(t1)
    t3 = np.arccos(((py / c1) ** 2 + (pz - 8) ** 2 - 162) / 162)
    c3, s3 = np.cos(t3), np.sin(t3)
    t2 = np.arccos((c1 * (pz - 8) * (1 + c3) + py * s3) / (18 * (1 + c3) * c1))
    return np.array([t1, t2, t3])


def test_lecture_3r_matches_its_printed_inverse_kinematics():
    arm = robots.load("lecture_3r")
    hand = arm.frame_id(arm.end_effector)
    for row in LECTURE_TABLE:
        q = lecture_inverse_kinematics(row[:3])
        assert frame_pose(arm, q, hand).translation == pytest.approx(row[:3] * INCH, abs=1e-12)


def test_lecture_cartesian_table():
    """The 11 points of the line (9, 6, 10) -> (3, 5, 8) in, solved by damped least squares
    continued from the start: the lecture's joint angles within 0.1 degree."""
    arm = robots.load("lecture_3r")
    hand = arm.frame_id(arm.end_effector)
    start, goal = np.array([9.0, 6.0, 10.0]), np.array([3.0, 5.0, 8.0])
    q = lecture_inverse_kinematics(start)
    for k, row in enumerate(LECTURE_TABLE):
        point = start + k / 10 * (goal - start)
        assert point == pytest.approx(row[:3], abs=1e-12)
        result = solve_ik(arm, q, hand, point * INCH)
        assert result.error < 1e-10
        q = result.q
        assert np.degrees(q) == pytest.approx(row[3:], abs=0.1)
        assert q == pytest.approx(lecture_inverse_kinematics(point), abs=1e-8)


def _fk(arm, frame, q):
    return np.array([frame_pose(arm, row, arm.frame_id(frame)).translation for row in q])


def test_lecture_line_over_http(client):
    start = lecture_inverse_kinematics(np.array([9.0, 6.0, 10.0]))
    body = {
        "robot": "lecture_3r",
        "path": {"kind": "cartesian", "start": start.tolist(), "positions": [[9 * INCH, 6 * INCH, 10 * INCH], [3 * INCH, 5 * INCH, 8 * INCH]]},
        "timing": {"method": "phase_plane"},
        "output": {"dt": 0.002},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    q = np.array(response.json()["samples"]["q"])
    arm = robots.load("lecture_3r")
    points = _fk(arm, "hand", q)
    a, b = np.array([9, 6, 10]) * INCH, np.array([3, 5, 8]) * INCH
    direction = (b - a) / np.linalg.norm(b - a)
    offsets = points - a
    distance = np.linalg.norm(offsets - np.outer(offsets @ direction, direction), axis=1)
    assert distance.max() <= 1e-4
    assert points[-1] == pytest.approx(b, abs=1e-9)
    assert q[-1] == pytest.approx(lecture_inverse_kinematics(np.array([3.0, 5.0, 8.0])), abs=1e-8)


def test_ur5_pose_line_keeps_orientation(client):
    arm = robots.load("ur5")
    start = np.array([0.3, -1.6, 1.7, -1.6, -1.57, 0.2])
    pose = frame_pose(arm, start, arm.frame_id("tool0"))
    quaternion = pin.Quaternion(pose.rotation)
    orientation = [quaternion.x, quaternion.y, quaternion.z, quaternion.w]
    targets = [
        [*(pose.translation + [0.0, 0.15, 0.0]), *orientation],
        [*(pose.translation + [0.1, 0.15, -0.1]), *orientation],
    ]
    body = {"robot": "ur5", "path": {"kind": "cartesian", "start": start.tolist(), "poses": targets}, "output": {"dt": 0.005}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    q = np.array(result["samples"]["q"])
    for row in q[:: max(1, len(q) // 40)]:
        rotation = frame_pose(arm, row, arm.frame_id("tool0")).rotation
        assert np.linalg.norm(pin.log3(rotation @ pose.rotation.T)) < 1e-3
    assert _fk(arm, "tool0", q[-1:])[0] == pytest.approx(targets[-1][:3], abs=1e-9)
    # A polyline stops at its corner: the joint velocity vanishes somewhere mid-way.
    speed = np.linalg.norm(np.array(result["samples"]["qd"]), axis=1)
    assert speed[len(speed) // 4 : 3 * len(speed) // 4].min() < 0.05 * speed.max()


@pytest.mark.parametrize(
    "points, words",
    [
        ([[0.0, 0.5, 0.3]], ["leaves the workspace", "% along the line to path.positions[0] (at [", "bring path.positions[0] within"]),
        ([[0.0, 0.0, 0.6]], ["singularity", "% along the line to path.positions[0]", "move path.positions[0] so that"]),
        ([[0.0, 0.5]], ["path.positions[0]"]),
        ([[1e9, 0.1, 0.2]], ["m long", "leaves the workspace"]),
    ],
)
def test_bad_lines_are_422(client, points, words):
    start = lecture_inverse_kinematics(np.array([9.0, 6.0, 10.0]))
    body = {"robot": "lecture_3r", "path": {"kind": "cartesian", "start": start.tolist(), "positions": points}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    for word in words:
        assert word in response.json()["detail"]


def test_repeated_points_of_a_line_are_dropped_with_a_warning(client):
    """A polyline stops at each point: a point repeated (positions), or a pose repeated with its
    quaternion scaled or negated (the same rotation), is dropped with a warning, and the answer
    is that of the line without it; it was refused ("repeats the previous point")."""
    arm = robots.load("ur5")
    start = np.array([0.3, -1.6, 1.7, -1.6, -1.57, 0.2])
    pose = frame_pose(arm, start, arm.frame_id("tool0"))
    quaternion = pin.Quaternion(pose.rotation)
    turn = [quaternion.x, quaternion.y, quaternion.z, quaternion.w]
    a, b = [*(pose.translation + [0.0, 0.15, 0.0]), *turn], [*(pose.translation + [0.1, 0.15, -0.1]), *turn]
    cases = [
        ("poses", [a, a[:3] + [-1.0004 * value for value in turn], b, b], [1, 3]),
        ("positions", [a[:3], b[:3], b[:3]], [2]),
    ]
    for field, points, dropped in cases:
        single = [point for index, point in enumerate(points) if index not in dropped]
        bodies = [{"robot": "ur5", "path": {"kind": "cartesian", "start": start.tolist(), field: given}, "output": {"dt": 0.005}}
                  for given in (points, single)]
        answer, reference = (client.post("/v1/trajectories", json=body) for body in bodies)
        assert answer.status_code == 200, answer.text[:300]
        assert answer.json()["duration"] == pytest.approx(reference.json()["duration"], rel=1e-12)  # the same rotation, to rounding
        (warning,) = [text for text in answer.json()["warnings"] if "dropped" in text]
        shown = f"path.{field}[{dropped[0]}] repeats" if len(dropped) == 1 else f"path.{field} [1, 3] repeat"
        assert warning.startswith(shown) and "the line stops at each point" in warning
