"""The search's compiled arm-to-obstacle distances (``toptraj.planners.generators.search.distance_kernels``,
used by ``free_space.point_distances``) against the numpy computation they replaced: the joint
frames of ``free_space.joint_placements`` and ``toptraj.planners.collision.distance.capsule_distance``,
on random configurations of three arms, for spheres, capsules and boxes (exact everywhere, and
exact only below a threshold, where the same configurations get the same lower bounds)."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners.collision import BoxObstacle, CapsuleObstacle, SphereObstacle
from toptraj.planners.collision.distance import capsule_distance
from toptraj.planners.generators.search.free_space import joint_placements, point_distances
from toptraj.robots.collision import robot_capsules

OBSTACLES = (
    SphereObstacle(np.array([0.45, 0.2, 0.3]), 0.08),
    CapsuleObstacle(np.array([0.3, -0.4, 0.1]), np.array([0.5, 0.4, 0.6]), 0.04),
    BoxObstacle(np.array([0.5, 0.1, 0.3]), np.array([0.2, 0.1, 0.3]), np.array([0.1, 0.2, 0.3, 0.927])),
)


def _numpy_distances(robot, q, obstacles, exact_below):
    capsules = robot_capsules(robot)
    joints = np.array([c.joint for c in capsules])
    local_a, local_b = np.array([c.a for c in capsules]), np.array([c.b for c in capsules])
    radius = np.array([c.radius for c in capsules])
    rotation, translation = joint_placements(robot, q)
    rotation, translation = rotation[:, joints], translation[:, joints]
    a = np.einsum("kcij,cj->kci", rotation, local_a) + translation
    b = np.einsum("kcij,cj->kci", rotation, local_b) + translation
    return np.min([capsule_distance(a, b, radius, o, exact_below).min(axis=1) for o in obstacles], axis=0)


@pytest.mark.parametrize("arm", ["geering_2r", "ur5", "panda"])
@pytest.mark.parametrize("exact_below", [np.inf, 0.05])
def test_compiled_distances_equal_the_numpy_ones(arm, exact_below):
    robot = robots.load(arm)
    rng = np.random.default_rng(7)
    low = np.where(np.isfinite(robot.limits.position_lower), robot.limits.position_lower, -np.pi)
    high = np.where(np.isfinite(robot.limits.position_upper), robot.limits.position_upper, np.pi)
    q = low + (high - low) * rng.random((300, robot.dof))
    for obstacles in ([OBSTACLES[0]], [OBSTACLES[1]], [OBSTACLES[2]], list(OBSTACLES)):
        ours = point_distances(robot, q, obstacles, exact_below)
        theirs = _numpy_distances(robot, q, obstacles, exact_below)
        np.testing.assert_allclose(ours, theirs, rtol=0.0, atol=1e-12)
        assert (ours < 0.0).any() or arm == "geering_2r"  # some configurations collide


def test_compiled_capsule_ends_equal_the_numpy_frames():
    from toptraj.planners.generators.search.distance_kernels import capsule_ends
    from toptraj.planners.generators.search.free_space import chain_tables

    robot = robots.load("panda")
    q = np.random.default_rng(3).uniform(-2.0, 2.0, (50, robot.dof))
    capsules = robot_capsules(robot)
    joints = np.array([c.joint for c in capsules])
    rotation, translation = joint_placements(robot, q)
    expected = np.einsum("kcij,cj->kci", rotation[:, joints], np.array([c.b for c in capsules])) + translation[:, joints]
    a, b = capsule_ends(q, *chain_tables(robot)[0])
    np.testing.assert_allclose(b, expected, rtol=0.0, atol=1e-12)
    assert a.shape == b.shape == (50, len(capsules), 3)
