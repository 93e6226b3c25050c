"""The search keeps the arm's links apart (issue 37, "checked ... always by the search"): a panda
motion whose straight joint line the self-collision check refuses (panda_link6 onto the base's
capsule) routes around, and the path the search returns is free of self-collision by coal's
distance between the collision meshes."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.planners.collision.self_collision import SelfCollision, check_self_collision, self_pairs
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.generators.search.curve import GridSplinePath
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.paths import SplinePath
from toptraj.robots.catalog import example_urdf_path

#: Two panda configurations whose straight joint line brings panda_link6 into panda_link0.
START = np.array([1.83, -1.53, 2.71, -2.02, 2.84, 0.67, -1.0])
GOAL = np.array([1.11, -1.76, 1.69, -2.56, 2.07, 1.15, -1.06])


def mesh_distance(name: str, joint_names: tuple[str, ...]):
    """A function of (q (n_dof,) of ``joint_names``, link, link) giving coal's smallest distance
    (m, 0 when they overlap) between the collision meshes of two links of the example arm
    ``name`` (its other joints, the fingers, at their neutral values)."""
    path = example_urdf_path(name)
    model = pin.buildModelFromUrdf(path)
    geometry = pin.buildGeomFromUrdf(model, path, pin.COLLISION, package_dirs=[path.split("/example-robot-data/")[0]])
    data, geometry_data = model.createData(), pin.GeometryData(geometry)
    of_link: dict[str, list[int]] = {}
    for k, item in enumerate(geometry.geometryObjects):
        of_link.setdefault(model.frames[item.parentFrame].name, []).append(k)

    index = [model.joints[model.getJointId(joint)].idx_q for joint in joint_names]

    def distance(q: np.ndarray, link_a: str, link_b: str) -> float:
        configuration = pin.neutral(model)
        configuration[index] = q
        pin.updateGeometryPlacements(model, data, geometry, geometry_data, configuration)
        objects, placements = geometry.geometryObjects, geometry_data.oMg
        return min(
            coal.distance(objects[a].geometry, placements[a], objects[b].geometry, placements[b], coal.DistanceRequest(), coal.DistanceResult())
            for a in of_link.get(link_a, []) for b in of_link.get(link_b, [])
        )

    return distance, of_link


@pytest.mark.parametrize("lazy", [False, None], ids=["every span checked", "lazily"])
def test_the_search_routes_around_a_straight_line_that_folds_the_arm_onto_itself(lazy):
    robot = robots.load("panda")
    distance, of_link = mesh_distance("panda", robot.joint_names)
    with pytest.raises(SelfCollision) as straight:
        check_self_collision(SplinePath(np.array([START, GOAL])), robot)
    assert {straight.value.link_a, straight.value.link_b} == {"panda_link0", "panda_link6"}
    # the capsules are conservative: panda's meshes are still 0.13 m apart where the capsules touch
    # (``toptraj.planners.collision.self_collision``, "Conservative")
    q_at = START + straight.value.s * (GOAL - START)
    assert 0.0 < distance(q_at, "panda_link0", "panda_link6") < 0.15

    found = global_search(
        robot, robot.limits, ("velocity", "acceleration"), START, GOAL, SearchOptions(tubes=1, roadmap_points=80, lazy=lazy),
        deadline=Deadline(120.0),
    )
    if lazy is False:  # every span checked: with no obstacles, pieces are removed by self-collision
        assert found.result.statistics.removed_by_obstacles > 0
    path = GridSplinePath(found.result.tubes[0].points)
    q = path.evaluate(np.linspace(0.0, 1.0, 121)).q
    assert np.allclose(q[0], START) and np.allclose(q[-1], GOAL)
    checked = [(a, b) for a, b in self_pairs(robot).links if a in of_link and b in of_link]
    assert ("panda_link0", "panda_link6") in checked
    nearest = min(distance(row, a, b) for row in q for a, b in checked)
    assert nearest > 0.0
