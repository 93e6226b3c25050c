"""Zones (``toptraj.planners.problem.zones``, ``toptraj.planners.constraints.zones``): limits of
their own on part of a path, held in one timing. The weld line of the README (ur5's tool along a
straight line at 5 cm/s) gets a slower zone over its middle third; the tool speed recomputed
from the returned samples by Pinocchio (its Jacobian, not the planner's tool-speed code) holds
and reaches the zone's limit there, and exceeds it elsewhere."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial import cKDTree

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.planners import METHODS, CartesianLine, LimitRequest, Sampling, WaypointPath, build_problem, plan
from toptraj.planners.checks.gate import samples_exceed
from toptraj.planners.collision import BoxObstacle, SphereObstacle
from toptraj.planners.constraints.zones import with_edges
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.problem import zones as zones_module
from toptraj.planners.problem.waypoints import make_path
from toptraj.planners.problem.zones import Zone
from toptraj.planners.trajectory import Samples
from toptraj.robots import LimitZone

UR5_START = np.array([0.3, -1.6, 1.7, -1.6, -1.57, 0.2])
WELD = CartesianLine(start=UR5_START, positions=np.array([[0.413, 0.542, 0.286]]))
SPEED, ZONE_SPEED = 0.05, 0.02
MIDDLE = Zone(s_range=(1 / 3, 2 / 3), tool_speed=ZONE_SPEED)
DT = 0.002


@pytest.fixture(scope="module")
def ur5():
    return robots.load("ur5")


def _tool_points(arm, q: np.ndarray) -> np.ndarray:
    model, data, frame = arm.model, arm.model.createData(), arm.model.getFrameId(arm.end_effector)
    points = []
    for row in q:
        pin.framesForwardKinematics(model, data, arm.configuration(row))
        points.append(data.oMf[frame].translation.copy())
    return np.array(points)


def _tool_speeds(arm, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    model, data, frame = arm.model, arm.model.createData(), arm.model.getFrameId(arm.end_effector)
    speeds = []
    for row, velocity in zip(q, qd):
        jacobian = pin.computeFrameJacobian(model, data, arm.configuration(row), frame, pin.LOCAL_WORLD_ALIGNED)
        speeds.append(np.linalg.norm(jacobian[:3] @ velocity))
    return np.array(speeds)


def _path_s(arm, q: np.ndarray) -> np.ndarray:
    """The path parameter of each configuration of ``q`` on the weld line: the tool point's
    position along the line, inverted through the path's own (monotone) map s -> position."""
    path = make_path(arm, WELD)
    grid = np.linspace(0.0, 1.0, 20_001)
    along_grid = _tool_points(arm, path.evaluate(grid).q)
    start, direction = along_grid[0], along_grid[-1] - along_grid[0]
    position = (along_grid - start) @ direction
    assert np.all(np.diff(position) > 0.0)
    return np.interp((_tool_points(arm, q) - start) @ direction, position, grid)


@pytest.mark.parametrize("method", ["phase_plane", "toppra"])
def test_a_tool_speed_zone_binds_at_its_limit_there_and_nowhere_else(ur5, method):
    result = plan(build_problem(ur5, WELD, METHODS[method], limits=LimitRequest(tool_speed=SPEED, zones=(MIDDLE,)), sampling=Sampling(dt=DT)))
    samples = result.samples
    speed = _tool_speeds(ur5, samples.q, samples.qd)
    s = _path_s(ur5, samples.q)
    inside = (s >= 1 / 3) & (s <= 2 / 3)
    assert inside.sum() > 1000
    assert speed[inside].max() <= ZONE_SPEED * 1.005
    assert speed[inside].max() >= ZONE_SPEED * 0.995  # it binds
    assert speed[~inside].max() > ZONE_SPEED * 1.5  # and nowhere else: the weld's own 5 cm/s there
    assert speed.max() <= SPEED * 1.005
    (report,) = result.zones
    assert report.index == 0 and report.ranges == ((1 / 3, 2 / 3),)
    assert report.binding and abs(report.peak - 1.0) <= 0.005


def test_the_zoned_duration_lies_between_the_unzoned_one_and_the_zone_everywhere(ur5):
    durations = [
        plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=speed, zones=zones), sampling=Sampling(dt=0.01))).duration
        for speed, zones in ((SPEED, ()), (SPEED, (MIDDLE,)), (ZONE_SPEED, ()))
    ]
    unzoned, zoned, everywhere = durations
    # A third of the line at 2 instead of 5 cm/s costs about (1/0.02 - 1/0.05) m/s of it: a
    # third of the 0.316 m line, 3.2 s; the whole line at 2 cm/s, 9.5 s.
    assert unzoned + 2.8 < zoned < everywhere - 5.5


def test_a_zone_above_the_speed_reached_there_does_not_bind(ur5):
    result = plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=SPEED, zones=(Zone(s_range=(0.4, 0.6), tool_speed=0.08),)), sampling=Sampling(dt=0.01)))
    (report,) = result.zones
    assert not report.binding and report.peak == pytest.approx(SPEED / 0.08, rel=0.005)


def test_a_workspace_sphere_is_found_where_the_tool_point_enters_and_leaves_it(ur5):
    path = make_path(ur5, WELD)
    middle = _tool_points(ur5, path.evaluate(np.array([0.5])).q)[0]
    sphere = SphereObstacle(center=middle + np.array([0.0, 0.0, 0.01]), radius=0.05)
    result = plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=SPEED, zones=(Zone(region=sphere, tool_speed=ZONE_SPEED),)), sampling=Sampling(dt=0.01)))
    ((enter, leave),) = result.zones[0].ranges
    assert 0.2 < enter < 0.5 < leave < 0.8
    # Independently: the tool point by Pinocchio at the path's points is on the sphere at both
    # edges, outside just before entering and just after leaving, inside in between.
    at = np.array([enter, leave, enter - 1e-6, leave + 1e-6, 0.5 * (enter + leave)])
    distance = np.linalg.norm(_tool_points(ur5, path.evaluate(at).q) - sphere.center, axis=1)
    slope = 0.5  # |dp/ds| of the 0.32 m line is below 0.5 m per unit of s
    edge_s = 1e-9  # the zones' documented edge accuracy in s (this test's own figure)
    assert np.all(np.abs(distance[:2] - sphere.radius) <= slope * edge_s + 1e-12)
    assert np.all(distance[2:4] > sphere.radius) and distance[4] < sphere.radius
    assert result.zones[0].binding


@pytest.mark.parametrize(("kind", "factor"), [("velocity", 0.3), ("acceleration", 0.4), ("torque", 0.4)])
def test_a_zone_scales_the_joint_limits_of_its_kind_inside_it(ur5, kind, factor):
    """On joint waypoints, a factor on one kind of joint limit over [0.4, 0.6]: the samples
    there (each sample's s: its nearest point of the path, on a grid of 1e-5) stay within the
    factor times the robot's limits and reach them; the motion slows."""
    spec = WaypointPath(np.array(UR5_WAYPOINTS))
    free = plan(build_problem(ur5, spec, METHODS["phase_plane"], sampling=Sampling(dt=0.01)))
    zone = dataclasses.replace(Zone(s_range=(0.4, 0.6)), **{kind: factor})
    result = plan(build_problem(ur5, spec, METHODS["phase_plane"], limits=LimitRequest(zones=(zone,)), sampling=Sampling(dt=0.002)))
    assert result.duration > free.duration * 1.005
    grid = np.linspace(0.0, 1.0, 100_001)
    _, nearest = cKDTree(make_path(ur5, spec).evaluate(grid).q).query(result.samples.q)
    s = grid[nearest]
    values = {"velocity": result.samples.qd, "acceleration": result.samples.qdd, "torque": result.samples.tau}[kind]
    share = (np.abs(values) / getattr(ur5.limits, kind)).max(axis=1)
    inside = (s >= 0.4 + 1e-4) & (s <= 0.6 - 1e-4)
    assert inside.sum() > 100
    assert factor * 0.99 <= share[inside].max() <= factor * 1.005
    assert share[~inside].max() > factor * 1.1
    (report,) = result.zones
    assert report.binding and abs(report.peak - 1.0) <= 0.005


@pytest.mark.parametrize(
    ("zones", "words"),
    [
        ((Zone(s_range=(0.6, 0.4), tool_speed=0.1),), "zone 0 has the s-range"),
        ((Zone(s_range=(0.4, 0.4), tool_speed=0.1),), r"zone 0 has the s-range \[0.4, 0.4\]; give 0 <= s0 < s1"),
        ((MIDDLE, Zone(s_range=(0.2, 1.5), tool_speed=0.1)), "zone 1 has the s-range"),
        ((MIDDLE, MIDDLE, Zone(s_range=(0.2, 0.3), tool_speed=-1.0)), "zone 2 has a tool speed"),
        ((Zone(s_range=(0.2, 0.3), torque=-0.5),), "zone 0 has a torque factor"),
        ((Zone(s_range=(0.2, 0.3)),), "zone 0 sets no limit"),
        ((MIDDLE,) * 33, "33 zones are given; at most 32"),
    ],
)
def test_bad_zones_are_refused_naming_the_zone(ur5, zones, words):
    with pytest.raises(InvalidRequest, match=words):
        plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=SPEED, zones=zones), sampling=Sampling(dt=0.01)))


def test_methods_that_do_not_hold_zones_refuse_them(ur5):
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(ur5, WaypointPath(np.array(UR5_WAYPOINTS)), METHODS["quintic"], limits=LimitRequest(zones=(MIDDLE,)), sampling=Sampling(dt=0.01)))
    assert (refused.value.field, refused.value.rule, refused.value.method) == ("zones", "zones_not_served", "quintic")
    assert str(refused.value) == (
        "zones are held by the timing methods phase_plane, toppra along a given path (waypoints interpolated by spline, "
        "linear or blend, or a cartesian line), not by 'quintic' here; use one of those, or leave the zones out"
    )


def test_a_box_that_is_not_turned_by_a_unit_quaternion_is_refused_in_a_sentence(ur5):
    """The refusal is the library's sentence with the zone's field, not a field made of the sentence."""
    box = BoxObstacle(center=(0.4, 0.5, 0.3), size=(0.1, 0.1, 0.1), orientation=(0.0, 0.0, 0.0, 0.5))
    with pytest.raises(InvalidRequest) as refused:
        plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(zones=(Zone(region=box, velocity=0.5),)), sampling=Sampling(dt=0.01)))
    assert (refused.value.field, refused.value.rule, refused.value.norm) == ("zones[0].box.orientation", "zone_box_not_unit", 0.5)
    assert str(refused.value) == "zone 0's box orientation has norm 0.5, not a unit quaternion [qx, qy, qz, qw]"


def test_the_grid_holds_every_zone_edge_and_keeps_its_knots():
    knots = np.array([0.0, 0.25, 0.5, 1.0])
    s = np.linspace(0.0, 1.0, 101)
    zones = (LimitZone(0, ((0.2501, 0.3337),), velocity=0.5), LimitZone(1, ((0.6, 0.60004), (0.9, 1.0)), tool_speed=0.1))
    grid = with_edges(s, zones, knots)
    assert np.all(np.isin([0.2501, 0.3337, 0.6, 0.60004, 0.9, 1.0], grid)) and np.all(np.isin(knots, grid))
    assert np.all(np.diff(grid) > 0.0) and grid[0] == 0.0 and grid[-1] == 1.0
    assert len(grid) <= len(s) + 4  # points near an edge moved onto it


def test_the_samples_check_holds_each_sample_to_the_limits_in_force_at_its_s(ur5):
    """A sample within the robot's velocity limits but above half of them inside a zone of
    factor 0.5 exceeds; the same sample outside the zone does not."""
    n = ur5.dof
    qd = np.zeros((3, n))
    qd[1, 2] = 0.7 * ur5.limits.velocity[2]
    zone = LimitZone(0, ((0.4, 0.6),), velocity=0.5)
    limits = dataclasses.replace(ur5.limits, zones=(zone,))
    for s_middle, expected in ((0.5, ("velocity", 1, 2)), (0.7, None)):
        samples = Samples(t=np.arange(3.0), q=np.zeros((3, n)), qd=qd, qdd=np.zeros((3, n)), tau=np.zeros((3, n)),
                          s=np.array([0.0, s_middle, 1.0]))
        assert samples_exceed(samples, limits, 1.003, ("velocity",)) == expected


def test_zones_that_cover_too_many_stretches_of_the_path_are_refused(ur5, monkeypatch):
    monkeypatch.setattr(zones_module, "MAX_RANGES", 1)
    sphere = SphereObstacle(center=np.array([0.413, 0.39, 0.34]), radius=0.05)  # the line's middle
    zones = (Zone(region=sphere, tool_speed=ZONE_SPEED), MIDDLE)
    with pytest.raises(InvalidRequest, match="more than 1 stretches of the path from zone 1 on"):
        plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=SPEED, zones=zones), sampling=Sampling(dt=0.01)))


def _beside_the_weld(arm, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The tool point at s = 0.5 of the weld line, and a point ``gap`` m from it at right angles
    to the (straight) line."""
    ends = _tool_points(arm, make_path(arm, WELD).evaluate(np.array([0.0, 0.5, 1.0])).q)
    direction = (ends[2] - ends[0]) / np.linalg.norm(ends[2] - ends[0])
    across = np.cross(direction, [0.0, 0.0, 1.0])
    return ends[1], ends[1] + gap * across / np.linalg.norm(across)


def test_a_region_the_path_never_enters_is_noted_with_its_closest_approach(ur5):
    """A sphere of radius 0.05 m centred 0.15 m beside the middle of the straight weld line: the
    tool point passes 0.10 m outside it at s = 0.5 (the line's nearest point to the centre)."""
    _, center = _beside_the_weld(ur5, 0.15)
    zones = (MIDDLE, Zone(region=SphereObstacle(center=center, radius=0.05), velocity=0.5))
    result = plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=SPEED, zones=zones), sampling=Sampling(dt=0.01)))
    assert result.zones[1].ranges == ()
    (note,) = [item for item in result.warnings if getattr(item, "rule", None) == "missed_region"]
    assert (note.facts["index"], note.facts["region"], note.facts["frame"]) == (1, "sphere", ur5.end_effector)
    # The scan's step along the 0.32 m line is 1.6e-4 m: the sampled closest point is within it
    # of s = 0.5, which moves the distance by (1.6e-4)^2 / (2 * 0.15) < 1e-7 m.
    assert note.facts["distance"] == pytest.approx(0.10, abs=1e-6)
    assert note.facts["at_s"] == pytest.approx(0.5, abs=1e-3)


def test_a_region_grown_by_the_noted_distance_applies(ur5):
    """The note's advice is followable: a radius above 0.05 m plus the noted distance makes the
    zone apply, and no note is left."""
    _, center = _beside_the_weld(ur5, 0.15)
    zone = Zone(region=SphereObstacle(center=center, radius=0.05 + 0.10 + 1e-3), velocity=0.5)
    result = plan(build_problem(ur5, WELD, METHODS["phase_plane"], limits=LimitRequest(tool_speed=SPEED, zones=(zone,)), sampling=Sampling(dt=0.01)))
    assert result.zones[0].ranges != ()
    assert not [item for item in result.warnings if getattr(item, "rule", None) == "missed_region"]
