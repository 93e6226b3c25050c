"""Blended corners (``path.interpolation = "blend"``): straight joint segments joined by circular
blends within ``path.max_deviation`` (Kunz & Stilman 2012, MoveIt's TOTG path), timed
time-optimally. The durations MoveIt 2's ``test_time_optimal_trajectory_generation.cpp``
asserts are reproduced through the service with the test's waypoints and limits, on an uploaded
arm with as many free joints (velocity and acceleration limits only, no dynamics)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj.planners.paths.blended import BlendedPath
from toptraj.planners.paths.grid import path_grid

#: MoveIt 2 TOTG test, tests "test2" and "test3": 4 joints, max_deviation 100.
TOTG_WAYPOINTS = [
    [1427.0, 368.0, 690.0, 90.0],
    [1427.0, 368.0, 790.0, 90.0],
    [952.499938964844, 433.0, 1051.0, 90.0],
    [452.5, 533.0, 1051.0, 90.0],
    [452.5, 533.0, 951.0, 90.0],
]
TOTG_VELOCITY = [1.3, 0.67, 0.67, 0.5]
#: Durations asserted there: with a 10 s integration time step, and with the default 1 ms.
TOTG_DURATION_10S_STEP = 1922.1418427445944
TOTG_DURATION = 1919.5597888812974


def free_joints_urdf(n_joints: int) -> str:
    """A chain of ``n_joints`` prismatic joints with position limits of +-1e4 (the test's
    waypoints are large numbers in their joint units), each moving a 1 kg link."""
    axes = ("1 0 0", "0 1 0", "0 0 1")
    parts = ['<?xml version="1.0"?>', f'<robot name="free_{n_joints}">', '<link name="base"/>']
    parent = "base"
    for k in range(n_joints):
        parts.append(
            f'<joint name="j{k}" type="prismatic"><parent link="{parent}"/><child link="l{k}"/>'
            f'<axis xyz="{axes[k % 3]}"/><limit lower="-10000" upper="10000" effort="1000" velocity="10"/></joint>'
        )
        parts.append(
            f'<link name="l{k}"><inertial><mass value="1"/>'
            '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
        )
        parent = f"l{k}"
    parts.append("</robot>")
    return "\n".join(parts)


@pytest.fixture(scope="module")
def free_arms(client):
    names = {}
    for n_joints in (4, 6):
        response = client.post("/v1/robots", json={"name": f"free_{n_joints}", "urdf": free_joints_urdf(n_joints)})
        assert response.status_code == 201, response.text
        names[n_joints] = response.json()["name"]
    return names


def _totg_request(robot, waypoints, velocity, acceleration, max_deviation, method="phase_plane", dt=1.0):
    return {
        "robot": robot,
        "path": {"kind": "waypoints", "waypoints": waypoints, "interpolation": "blend", "max_deviation": max_deviation},
        "timing": {
            "method": method,
            "constraints": ["velocity", "acceleration"],
            "limits": {"velocity": velocity, "acceleration": acceleration},
        },
        "output": {"dt": dt},
    }


# min_cost (a convex program over the whole grid) is left out: on this long blended path it
# takes most of the synchronous 20 s budget on a loaded machine.
@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
def test_moveit_totg_four_joint_path(client, free_arms, method):
    """TOTG tests "test2" (10 s time step) and "test3" (1 ms): five waypoints, max_deviation
    100, accelerations 0.002. Our duration matches both within 1 %; it is within 0.1 % of the
    fine-step value, the time-optimal one."""
    body = _totg_request(free_arms[4], TOTG_WAYPOINTS, TOTG_VELOCITY, [0.002] * 4, 100.0, method)
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    assert result["duration"] == pytest.approx(TOTG_DURATION_10S_STEP, rel=0.01)
    assert result["duration"] == pytest.approx(TOTG_DURATION, rel=0.01)
    assert result["duration"] == pytest.approx(TOTG_DURATION, rel=1e-3)
    utilization = result["peak_utilization"]
    assert max(utilization["velocity"]) <= 1.003 and max(utilization["acceleration"]) <= 1.003
    assert max(utilization["acceleration"]) > 0.99
    q = np.array(result["samples"]["q"])
    assert q[0] == pytest.approx(TOTG_WAYPOINTS[0], abs=1e-9)
    assert q[-1] == pytest.approx(TOTG_WAYPOINTS[-1], abs=1e-9)
    # The motion never stops between its ends: the blends let it flow through the corners.
    speed = np.linalg.norm(np.array(result["samples"]["qd"]), axis=1)
    assert speed[1:-1].min() > 0.0


def test_moveit_totg_two_waypoints(client, free_arms):
    """TOTG test "test1": a straight line (nothing to blend), accelerations 0.00249: the
    duration asserted there, 40.0803 s (bang-bang: 2 sqrt(L / a))."""
    waypoints = [[1424.0, 984.999694824219, 2126.0, 0.0], [1423.0, 985.000244140625, 2126.0, 0.0]]
    body = _totg_request(free_arms[4], waypoints, TOTG_VELOCITY, [0.00249] * 4, 100.0, dt=0.1)
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    assert response.json()["duration"] == pytest.approx(40.080256821829849, rel=1e-3)


def test_moveit_totg_large_acceleration_case(client, free_arms):
    """TOTG test "testLargeAccel": six joints, path tolerance 0.1, a very short first segment.
    MoveIt asserts accelerations below 100; here every sample holds the limits themselves."""
    waypoints = [
        [1.6113056281076339, -0.21400163389235427, -1.974502599739185, 9.9653618690354051e-12, -1.3810916877429624, 1.5293902838041467],
        [1.6088016187976597, -0.21792862470933924, -1.9758628799742952, 0.00010424017303217738, -1.3835690515335755, 1.5279972853269816],
        [1.5887695443178671, -0.24934455124521923, -1.9867451218551782, 0.00093816147756670078, -1.4033879618584812, 1.5168532975096607],
        [1.1647412393815282, -0.91434018564402375, -2.2170946337498498, 0.018590164397622583, -1.8229041212673529, 1.2809632867583278],
    ]
    velocity = [0.89535390627300004, 0.89535390627300004, 0.79587013890930003, 0.92022484811399996, 0.82074108075029995, 1.3927727430915]
    acceleration = [0.82673490883799994, 0.78539816339699997, 0.60883578557700002, 3.2074759432319997, 1.4398966328939999, 4.7292792634680003]
    body = _totg_request(free_arms[6], waypoints, velocity, acceleration, 0.1, dt=0.001)
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    result = response.json()
    qd, qdd = np.array(result["samples"]["qd"]), np.array(result["samples"]["qdd"])
    assert np.abs(qd / velocity).max() <= 1.003
    assert np.abs(qdd / acceleration).max() <= 1.003
    assert max(result["peak_utilization"]["acceleration"]) <= 1.003


def test_blends_stay_within_the_deviation_and_keep_the_tangent():
    rng = np.random.default_rng(4)
    for _ in range(12):
        waypoints = rng.uniform(-2.0, 2.0, size=(int(rng.integers(3, 7)), 5))
        deviation = float(rng.uniform(0.01, 1.0))
        path = BlendedPath(waypoints, deviation)
        # Dense samples and the middle of every piece (the point of a blend closest to its corner).
        s = np.union1d(np.linspace(0.0, 1.0, 10_001), 0.5 * (path.knots[:-1] + path.knots[1:]))
        points = path.evaluate(s)
        # Arc length: |dq/ds| is the path's length everywhere (no kinks in random paths).
        assert path.kinks.size == 0
        assert np.linalg.norm(points.dq, axis=1) == pytest.approx(path.length, rel=1e-9)
        assert points.q[0] == pytest.approx(waypoints[0]) and points.q[-1] == pytest.approx(waypoints[-1])
        for k, waypoint in enumerate(waypoints[1:-1]):
            closest = np.linalg.norm(points.q - waypoint, axis=1).min()
            assert closest <= deviation * (1 + 1e-9)
            assert closest == pytest.approx(path.deviations[k], rel=1e-9)
        # q and dq/ds continuous at every knot, d2q/ds2 jumps only at the breaks.
        inner = path.knots[1:-1]
        left, right = path.evaluate(inner, "left"), path.evaluate(inner, "right")
        assert left.q == pytest.approx(right.q, abs=1e-12)
        assert left.dq == pytest.approx(right.dq, abs=1e-9 * path.length)
        assert set(path.breaks) == set(inner)
        # The derivatives are those of q: central differences.
        h = 1e-6
        middle = 0.5 * (path.knots[:-1] + path.knots[1:])
        ahead, behind = path.evaluate(middle + h), path.evaluate(middle - h)
        here = path.evaluate(middle)
        assert (ahead.q - behind.q) / (2 * h) == pytest.approx(here.dq, rel=1e-6, abs=1e-6 * path.length)
        assert (ahead.dq - behind.dq) / (2 * h) == pytest.approx(here.ddq, rel=1e-5, abs=1e-5 * path.length**2)
        assert (ahead.ddq - behind.ddq) / (2 * h) == pytest.approx(
            path.third_derivative(middle), rel=1e-4, abs=1e-4 * path.length**3
        )


def test_blend_geometry_follows_kunz_and_stilman():
    """A right angle in the plane: the blend touches each segment at l = min(half segment,
    delta sin(a/2) / (1 - cos(a/2))) from the corner, with radius l / tan(a/2)."""
    waypoints = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 2.0]])
    for deviation, touch in ((0.1, 0.1 * np.sin(np.pi / 4) / (1 - np.cos(np.pi / 4))), (10.0, 1.0)):
        path = BlendedPath(waypoints, deviation)
        radius = touch / np.tan(np.pi / 4)
        assert path.length == pytest.approx(6.0 - 2 * touch + np.pi / 2 * radius)
        assert path.deviations[0] == pytest.approx(min(deviation, radius * (np.sqrt(2) - 1)))
        arc = path.evaluate(np.array([0.5 * (path.knots[1] + path.knots[2])]))
        assert np.linalg.norm(arc.ddq) / path.length**2 == pytest.approx(1.0 / radius)


def test_a_reversal_is_a_stop_and_a_straight_continuation_is_no_blend():
    path = BlendedPath(np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.0], [0.5, 1.0]]), 0.1)
    assert path.kinks.size == 1
    assert path(path.kinks)[0] == pytest.approx([1.0, 0.0])
    straight = BlendedPath(np.array([[0.0, 0.0], [1.0, 1.0], [3.0, 3.0]]), 0.1)
    assert straight.kinks.size == 0 and len(straight.knots) == 3
    assert straight.deviations == pytest.approx([0.0])


def test_the_grid_resolves_every_blend():
    path = BlendedPath(np.array(UR5_WAYPOINTS), 0.05)
    for n in (None, 50):
        s = path_grid(path, n)
        assert np.isin(path.knots, s).all()
        per_piece = np.diff(np.searchsorted(s, path.knots))
        assert per_piece.min() >= 8


def test_ur5_blended_corners_beat_stopping_at_them(client):
    """The same waypoints, stopping at each (linear) and blended: the blends save time, and
    every limit (torque included) holds."""
    durations = {}
    for interpolation in ("linear", "blend"):
        body = {
            "robot": "ur5",
            "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": interpolation,
                     **({"max_deviation": 0.2} if interpolation == "blend" else {})},
            "timing": {"method": "phase_plane"},
        }
        response = client.post("/v1/trajectories", json=body)
        assert response.status_code == 200, response.text
        result = response.json()
        durations[interpolation] = result["duration"]
        for values in result["peak_utilization"].values():
            assert max(values) <= 1.003
    assert durations["blend"] < 0.9 * durations["linear"]


@pytest.mark.parametrize(
    "path, words",
    [
        ({"interpolation": "spline", "max_deviation": 0.1}, ["max_deviation", "'blend'"]),
        ({"interpolation": "blend", "max_deviation": 0.0}, ["max_deviation"]),
        ({"interpolation": "blend", "max_deviation": -1.0}, ["max_deviation"]),
    ],
)
def test_bad_blends_are_422(client, path, words):
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, **path}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    for word in words:
        assert word in response.text


@pytest.mark.parametrize("method", ["phase_plane", "toppra", "min_cost"])
def test_a_blend_too_small_to_follow_is_a_corner_where_the_motion_stops(client, method):
    """max_deviation 1e-9 rad blends the UR5 corners over a few 1e-10 of the path, which no
    timing grid resolves (the acceleration limit was exceeded by 23 %): those corners are stops,
    the answer says so, and the motion is the stop-and-go one (linear interpolation)."""
    assert BlendedPath(np.array(UR5_WAYPOINTS), 1e-9).tight_corners == (1, 2)
    assert BlendedPath(np.array(UR5_WAYPOINTS), 1e-3).tight_corners == ()
    durations, answers = {}, {}
    for interpolation in ("linear", "blend"):
        body = {
            "robot": "ur5",
            "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": interpolation,
                     **({"max_deviation": 1e-9} if interpolation == "blend" else {})},
            "timing": {"method": method},
            "output": {"dt": 0.01},
        }
        response = client.post("/v1/trajectories", json=body)
        assert response.status_code == 200, response.text
        answers[interpolation] = response.json()
        durations[interpolation] = answers[interpolation]["duration"]
        for values in answers[interpolation]["peak_utilization"].values():
            assert max(values) <= 1.003
    assert durations["blend"] == pytest.approx(durations["linear"], rel=1e-9)
    assert any(
        "path.max_deviation = 1e-09 is too small to blend the corners at waypoints 1, 2" in warning
        and "the motion stops there" in warning
        for warning in answers["blend"]["warnings"]
    )


@pytest.mark.parametrize(
    "waypoints",
    [
        # geering_2r: a first segment of 9e-5 rad, half of it the blend's; then a long one
        [[-2.601765, -2.399498], [-2.60183, -2.399563], [0.297917, 2.923878], [0.297964, 2.923937], [0.294114, -2.487892]],
        # a short segment between two blends, shorter than 1e-5 of the path
        [[0.0, 0.0], [1.0, 0.0], [1.0, 4e-5], [2.0, 1.0]],
    ],
    ids=["short-first-segment", "short-middle-segment"],
)
def test_a_blended_path_leaves_the_first_waypoint_and_has_no_gap(waypoints):
    """A straight piece shorter than 1e-5 of the path, up to a blend, was left out: the path
    started 3.25e-5 rad from the first waypoint (half the short segment), and between two blends
    it jumped over such a gap."""
    path = BlendedPath(np.array(waypoints, dtype=float), 0.13)
    assert path.evaluate(np.array([0.0])).q[0] == pytest.approx(waypoints[0], abs=1e-15)
    assert path.evaluate(np.array([1.0])).q[0] == pytest.approx(waypoints[-1], abs=1e-15)
    junctions = path.knots[1:-1]
    left, right = path.evaluate(junctions, "left").q, path.evaluate(junctions, "right").q
    assert np.abs(left - right).max() <= 1e-12


def _length_of(waypoints: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())


def _recorded_curve(count: int) -> np.ndarray:
    """``count`` samples of a smooth ur5 motion recorded at a fixed rate, the arm slowing to rest
    at both ends (samples crowd there)."""
    u = (1.0 - np.cos(np.pi * np.linspace(0.0, 1.0, count))) / 2.0
    amplitude = np.array([0.8, 0.5, 0.6, 0.7, 0.6, 0.8])
    frequency, phase = np.array([0.5, 0.7, 0.4, 0.6, 0.3, 0.8]), np.array([0.3, 1.9, 4.0, 2.5, 5.1, 0.9])
    return amplitude * (np.sin(2 * np.pi * frequency * u[:, None] + phase) - np.sin(phase)) + [0.0, -1.5, 1.5, -1.5, 0.0, 0.0]


def test_a_dense_recording_blends_every_corner_and_leaves_no_sliver_of_line_on_it():
    """A corner between two short segments that turns by little has a short blend of large
    radius: it was a stop (its angle times its length, 2e-7 of the path, under MIN_BLEND), so
    300 samples of a smooth motion were 300 stops. Only a blend of small radius is one now; and
    a blend shrinks rather than leave a line shorter than MIN_LINE of the path before it (a line
    of 7.6e-8 of the path between two blends made toppra exceed the acceleration limit 8,000
    fold), its radius kept above MIN_BLEND: a zigzag whose blends would fall below it if shrunk
    keeps them as they are, and a corner too tight for any deviation is not blamed on it."""
    from toptraj.planners.paths.blended import MIN_BLEND, MIN_LINE

    path = BlendedPath(_recorded_curve(300), 0.1)
    assert path.tight_corners == ()
    assert np.min(np.diff(path.knots)) >= MIN_LINE * (1 - 1e-9)
    sharp = BlendedPath(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1e-6], [2.0, 1e-6]]), 0.1)
    assert sharp.tight_corners == (1, 2) and sharp.tight_by_deviation == ()  # radius 5e-7 of the path
    assert 5e-7 < MIN_BLEND
    assert BlendedPath(sharp.waypoints, 1e-12).tight_by_deviation == ()  # no deviation rounds it
    assert BlendedPath(np.array(UR5_WAYPOINTS), 1e-9).tight_by_deviation == (1, 2)
    turn = np.radians(170.0)  # a zigzag of two blends of radius 1.02e-5 of the path, 1e-6 apart:
    distance = 1.02e-5 * np.tan(turn / 2)  # the second, shrunk to leave MIN_LINE, would fall below MIN_BLEND
    unit = [np.array([np.cos(k * turn), np.sin(k * turn)]) for k in range(3)]
    zigzag = np.cumsum([[0.0, 0.0], 0.5 * unit[0], (2 * distance + 1e-6) * unit[1], 0.5 * unit[2]], axis=0)
    deviation = distance * 2 * np.sin(turn / 4) ** 2 / np.sin(turn / 2)
    for corner in BlendedPath(zigzag, deviation)._pieces:
        assert corner[0] == "line" or corner[4] > MIN_BLEND * _length_of(zigzag)


@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
def test_a_dense_recording_blended_takes_as_long_as_its_spline(client, method):
    """300 samples of a smooth motion: blended, every corner was a stop (7.4 s against the
    spline's 1.25 s); now the blend's motion takes the spline's time within 1 %, holding the
    limits, with no corner left unblended."""
    from tests.service.answer_limits import assert_limits_held

    waypoints = _recorded_curve(300).tolist()
    answers = {}
    for interpolation in ("spline", "blend"):
        body = {"robot": "ur5", "path": {"waypoints": waypoints, "interpolation": interpolation},
                "timing": {"method": method}, "output": {"dt": 0.002}}
        response = client.post("/v1/trajectories", json=body)
        assert response.status_code == 200, response.text[:300]
        answers[interpolation] = response.json()
        assert_limits_held(body, answers[interpolation])
    assert answers["blend"]["duration"] == pytest.approx(answers["spline"]["duration"], rel=0.01)
    assert not [warning for warning in answers["blend"]["warnings"] if "stops there" in warning]
