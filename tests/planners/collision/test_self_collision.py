"""Self-collision along given paths: a ur5 folding onto itself is refused naming the two links
and s, checked against coal's distance between the links' collision meshes; a normal path
passes (coal agrees the meshes stay apart); allowed pairs are not checked; the search refuses a
start whose links touch and keeps its pieces' links apart."""

from __future__ import annotations

import dataclasses

import coal
import numpy as np
import pinocchio as pin
import pytest

from tests.planners.collision.test_obstacles import _coal_capsule
from toptraj import robots
from toptraj.planners.collision.self_collision import (
    PADDING,
    SelfCollision,
    check_self_collision,
    pair_distances,
    self_pairs,
)
from toptraj.planners.generators.search.free_space import free_distances
from toptraj.planners.paths import SplinePath
from toptraj.robots.catalog import example_urdf_path
from toptraj.robots.collision import robot_capsules as robot_capsules_of
from toptraj.robots.collision import world_capsules

UPRIGHT = np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0])
FOLDED = np.array([0.0, -1.57, 2.9, -1.57, 0.0, 0.0])
#: A path that folds the elbow shut: the forearm comes down onto the shoulder.
FOLDING = np.array([UPRIGHT, (UPRIGHT + FOLDED) / 2.0, FOLDED])
#: An everyday motion of the arm.
NORMAL = np.array([UPRIGHT, [0.5, -1.2, 1.0, -1.0, 0.5, 0.0], [1.0, -1.0, 1.5, -1.57, 1.0, 1.0]])


@pytest.fixture(scope="module")
def meshes():
    """ur5's model, collision meshes and a function giving coal's distance (m) between the
    meshes of two links at a configuration (0 when they overlap)."""
    path = example_urdf_path("ur5")
    model = pin.buildModelFromUrdf(path)
    geometry = pin.buildGeomFromUrdf(model, path, pin.COLLISION, package_dirs=[path.split("/example-robot-data/")[0]])
    data, geometry_data = model.createData(), pin.GeometryData(geometry)
    index = {model.frames[item.parentFrame].name: k for k, item in enumerate(geometry.geometryObjects)}

    def distance(q, link_a, link_b):
        pin.updateGeometryPlacements(model, data, geometry, geometry_data, q)
        a, b = index[link_a], index[link_b]
        result = coal.DistanceResult()
        return coal.distance(
            geometry.geometryObjects[a].geometry, geometry_data.oMg[a], geometry.geometryObjects[b].geometry,
            geometry_data.oMg[b], coal.DistanceRequest(), result,
        )

    return distance


def _capsule_distance(robot, q, link_a, link_b):
    """coal's distance between the capsules of two links at ``q`` (n_dof,)."""
    pairs = self_pairs(robot)
    capsules = list(pairs.capsules)
    a, b = world_capsules(robot.model, robot.data, capsules, robot.configuration(q[None, :]))
    i = next(k for k, c in enumerate(capsules) if c.link == link_a)
    j = next(k for k, c in enumerate(capsules) if c.link == link_b)
    first, second = _coal_capsule(a[0, i], b[0, i], capsules[i].radius), _coal_capsule(a[0, j], b[0, j], capsules[j].radius)
    return coal.distance(first[0], first[1], second[0], second[1], coal.DistanceRequest(), coal.DistanceResult())


def test_a_ur5_folding_onto_itself_is_refused_naming_the_links_and_s(meshes):
    robot = robots.load("ur5")
    path = SplinePath(FOLDING)
    with pytest.raises(SelfCollision) as refused:
        check_self_collision(path, robot)
    error = refused.value
    assert {error.link_a, error.link_b} == {"shoulder_link", "forearm_link"}
    assert "'shoulder_link'" in error.detail and "'forearm_link'" in error.detail and f"s = {error.s:.4g}" in error.detail
    q_at = path.evaluate(np.array([error.s])).q[0]
    # the capsules (coal's own capsule distance) first touch at the s reported, to the check's resolution
    assert -1e-3 <= _capsule_distance(robot, q_at, error.link_a, error.link_b) <= 0.0
    before = path.evaluate(np.array([error.s - 0.01])).q[0]
    assert _capsule_distance(robot, before, error.link_a, error.link_b) > 0.0
    # the meshes (coal on ur5's collision meshes) are apart there, by less than the capsules' padding
    configuration = robot.configuration(q_at[None, :])[0]
    assert 0.0 <= meshes(configuration, error.link_a, error.link_b) < 0.1
    # and do collide further along: the refusal is of a real collision, reported no later than it
    folded = robot.configuration(FOLDED[None, :])[0]
    assert meshes(folded, error.link_a, error.link_b) == 0.0


def test_a_normal_path_passes_and_its_meshes_stay_apart(meshes):
    robot = robots.load("ur5")
    path = SplinePath(NORMAL)
    found = check_self_collision(path, robot)
    assert found.distance > 0.0
    pairs = self_pairs(robot)
    for q in path.evaluate(np.linspace(0.0, 1.0, 41)).q:
        configuration = robot.configuration(q[None, :])[0]
        for link_a, link_b in pairs.links:
            # the capsules contain the meshes: the meshes are at least as far apart
            assert meshes(configuration, link_a, link_b) >= min(found.distance, _capsule_distance(robot, q, link_a, link_b)) - 1e-9


def test_an_allowed_pair_is_not_checked():
    robot = robots.load("ur5")
    path = SplinePath(FOLDING)
    with pytest.raises(SelfCollision) as first:
        check_self_collision(path, robot)
    allowed = frozenset({("forearm_link", "shoulder_link")})
    assert ("shoulder_link", "forearm_link") not in self_pairs(robot, allowed).links
    with pytest.raises(SelfCollision) as second:
        check_self_collision(path, robot, allowed)
    assert {second.value.link_a, second.value.link_b} != {"shoulder_link", "forearm_link"}
    assert second.value.s > first.value.s
    # the default list: ur5's SRDF (example-robot-data) allows the forearm against the wrist
    assert ("forearm_link", "wrist_1_link") not in self_pairs(robot).links


def test_the_search_keeps_links_apart_and_refuses_a_folded_start():
    robot = robots.load("ur5")
    q = np.array([UPRIGHT, FOLDED])
    free = free_distances(robot, q, [], 0.01)
    # without obstacles: the clearance plus the links' smallest distance (coal's on the capsules)
    pairs = self_pairs(robot)
    expected = [0.01 + min(_capsule_distance(robot, row, a, b) for a, b in pairs.links) for row in q]
    assert free == pytest.approx(expected, abs=1e-9)
    assert free[1] < 0.01  # folded: below the clearance, so the search removes it
    from toptraj.planners.generators.search.problem import build_problem

    with pytest.raises(SelfCollision) as refused:
        build_problem(robot, robot.limits, ("velocity", "acceleration"), FOLDED, UPRIGHT)
    assert "path.start" in refused.value.detail and refused.value.s == 0.0


def test_the_capsules_never_accept_links_whose_meshes_touch(meshes):
    """Each pair's capsule distance is at most its meshes' distance (coal), at the fold and at
    sampled configurations: where the check accepts (capsules apart), the meshes are apart."""
    robot = robots.load("ur5")
    pairs = self_pairs(robot)
    q = np.vstack([SplinePath(FOLDING).evaluate(np.linspace(0.0, 1.0, 21)).q, np.random.default_rng(0).uniform(-np.pi, np.pi, (30, 6))])
    capsule = pair_distances(robot, pairs, q)
    for k, row in enumerate(q):
        configuration = robot.configuration(row[None, :])[0]
        for p, (link_a, link_b) in enumerate(pairs.links):
            assert meshes(configuration, link_a, link_b) >= capsule[k, p] - 1e-9


def test_the_capsules_refuse_a_fold_early_by_at_most_their_stated_padding(meshes):
    robot = robots.load("ur5")
    path = SplinePath(FOLDING)
    with pytest.raises(SelfCollision) as refused:
        check_self_collision(path, robot)
    q_at = path.evaluate(np.array([refused.value.s])).q[0]
    early = meshes(robot.configuration(q_at[None, :])[0], refused.value.link_a, refused.value.link_b)
    # the meshes are still 0.078 m apart where the capsules touch: within the padding the refusal states
    assert early == pytest.approx(0.078, abs=0.002)
    assert early <= PADDING
    assert f"padding of up to about {PADDING:g} m" in refused.value.detail


def test_a_payload_with_a_radius_is_kept_from_the_arms_own_links():
    from toptraj.robots import equipment

    robot = robots.load("ur5")
    start, goal = [3.03, -1.68, -1.5, -1.67, 1.27, 1.6], [3.03, -1.68, -2.5, -1.67, 1.27, 1.6]
    path = SplinePath(np.array([start, goal]))
    assert check_self_collision(path, robot).distance > 0.0  # the bare arm folds its elbow freely
    carrying = equipment.equip(robot, equipment.payload(1.0, [0.0, 0.0, 0.1], radius=0.08))
    with pytest.raises(SelfCollision) as refused:
        check_self_collision(path, carrying)
    assert {refused.value.link_a, refused.value.link_b} == {"upper_arm_link", "payload"}
    assert refused.value.detail.endswith("or give the payload a smaller collision radius")
    assert "collision meshes with a padding" in refused.value.detail  # ur5's upper arm is a mesh; the payload, its sphere
    # independently: coal between a sphere at tool0's placement of the centre of mass (Pinocchio) and
    # the upper arm's capsule; they first touch at the s reported
    data = robot.model.createData()
    capsules = robot_capsules_of(robot)
    upper = next(c for c in capsules if c.link == "upper_arm_link")

    def apart(s):
        q = robot.configuration(path.evaluate(np.array([s])).q)
        pin.framesForwardKinematics(robot.model, data, q[0])
        center = data.oMf[robot.model.getFrameId("tool0")].act(np.array([0.0, 0.0, 0.1]))
        a, b = world_capsules(robot.model, data, [upper], q)
        capsule = _coal_capsule(a[0, 0], b[0, 0], upper.radius)
        sphere = (coal.Sphere(0.08), coal.Transform3s(np.eye(3), center))
        return coal.distance(capsule[0], capsule[1], sphere[0], sphere[1], coal.DistanceRequest(), coal.DistanceResult())

    assert -1e-3 <= apart(refused.value.s) <= 1e-9 and apart(refused.value.s - 0.01) > 0.0


def test_a_refusal_says_what_the_capsules_are_and_offers_allowing_a_pair_only_where_it_can_be():
    """An arm without collision meshes (lecture_3r) is drawn as capsules of 0.03 m along its
    links: the refusal says so, not the catalog meshes' padding; allowing the pair is offered only
    for an upload (a catalog robot's allowed pairs cannot be changed)."""
    robot = robots.load("lecture_3r")
    folded = SplinePath(np.array([[0.0, 0.0, 0.0], [0.0, 2.9, 2.9]]))
    with pytest.raises(SelfCollision) as refused:
        check_self_collision(folded, robot)
    assert "a link without a collision mesh is a capsule of radius 0.03 m along it" in refused.value.detail
    assert "padding" not in refused.value.detail and refused.value.detail.endswith("so that the arm does not fold onto itself")
    uploaded = dataclasses.replace(robot, source="upload")
    with pytest.raises(SelfCollision) as refused:
        check_self_collision(folded, uploaded)
    assert refused.value.detail.endswith("or, if the links may touch, allow the pair among the robot's allowed collisions when uploading it")


def test_a_payload_sphere_overlapping_links_at_the_zero_pose_is_checked_against_them():
    """The pairs touching at the zero pose are allowed (the arm's own geometry), but not the
    payload's: a 2 m sphere engulfing the arm was planned without a word."""
    from toptraj.robots import equipment

    robot = robots.load("ur5")
    path = SplinePath(np.array([[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [0.8, -1.0, 1.4, -0.5, 0.9, 0.3]]))
    assert check_self_collision(path, robot).distance > 0.0
    engulfing = equipment.equip(robot, equipment.payload(1.0, [0.0, 0.0, 0.0], radius=2.0))
    with pytest.raises(SelfCollision) as refused:
        check_self_collision(path, engulfing)
    assert "payload" in (refused.value.link_a, refused.value.link_b) and refused.value.s == 0.0
