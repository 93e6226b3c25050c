"""A motion that no limit held bounds is refused before planning, with what bounds it: the paper
arms have torque limits only, so velocity or acceleration limits alone left the phase plane's
maximum velocity curve infinite (a division by zero in the timing, worded as a numerical
breakdown) and a cell timed at 0.2 ms with torques of 1e7 N m (a 200)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from fastapi.testclient import TestClient

from toptraj import robots
from toptraj.planners import METHODS, LimitRequest, WaypointPath, build_problem, plan
from toptraj.planners.errors import InvalidRequest
from toptraj.service.app import create_app
from toptraj.service.problems import detail
from toptraj.service.settings import Settings


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with TestClient(create_app(Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("bounded")))) as test_client:
        yield test_client


def _trajectory(constraints, method="phase_plane", **limits) -> dict:
    timing = {"method": method, "constraints": constraints} | ({"limits": limits} if limits else {})
    return {"robot": "geering_2r", "path": {"waypoints": [[0.0, 0.0], [1.0, 1.0]]}, "timing": timing}


@pytest.mark.parametrize("method", ["phase_plane", "toppra", "quintic", "jerk_limited"])
@pytest.mark.parametrize("constraints", [["velocity"], ["acceleration"], ["velocity", "acceleration"]])
def test_limits_the_robot_does_not_have_are_refused_naming_what_bounds_it(client, method, constraints):
    response = client.post("/v1/trajectories", json=_trajectory(constraints, method))
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert detail.startswith(f"nothing bounds the motion of geering_2r: it has no finite {constraints[0]}"), detail
    assert "add 'torque' to timing.constraints (geering_2r has finite limits of that kind)" in detail
    assert f'give the limits in timing.limits, e.g. "{constraints[0]}": one value per joint in rad/s' in detail


def test_either_remedy_plans_the_motion(client):
    with_torque = client.post("/v1/trajectories", json=_trajectory(["velocity", "torque"]))
    torque_only = client.post("/v1/trajectories", json=_trajectory(["torque"]))  # no velocity limit to hold: the same motion
    assert with_torque.status_code == 200 and with_torque.json()["duration"] == torque_only.json()["duration"]
    given = client.post("/v1/trajectories", json=_trajectory(["velocity"], velocity=[2.0, 2.0]))
    assert given.status_code == 200, given.text
    # 1 rad at 2 rad/s: 0.5 s, and on the grid of 100 intervals the first and last take twice
    # their time at full speed (x = sd^2 linear in s from rest), 0.01 s more
    assert given.json()["duration"] == pytest.approx(0.51, abs=1e-6)
    assert max(given.json()["peak_utilization"]["velocity"]) == pytest.approx(1.0, abs=5e-3)


def test_a_cell_of_arms_without_the_limits_asked_is_refused_and_with_torque_is_planned(client):
    arm = {"robot": "yamamoto_2r", "waypoints": [[0.0, 0.0], [1.0, 1.0]]}
    cell = {"arms": [arm, {**arm, "base": {"position": [3.0, 0.0, 0.0]}}], "constraints": ["velocity"]}
    refused = client.post("/v1/cells", json=cell)
    assert refused.status_code == 422, refused.text[:300]
    assert refused.json()["detail"] == (
        "arms[0]: nothing bounds the motion of yamamoto_2r: it has no finite velocity limit, so the shortest time would be "
        "zero; add 'torque' to constraints (yamamoto_2r has finite limits of that kind)"
    )
    planned = client.post("/v1/cells", json={**cell, "constraints": ["velocity", "torque"]})
    assert planned.status_code == 200, planned.text[:300]
    assert planned.json()["duration"] > 0.1
    assert max(planned.json()["arms"][0]["peak_utilization"]["torque"]) == pytest.approx(1.0, abs=5e-3)


def _planned(limits: dict, kinds: tuple[str, ...], waypoints, interpolation: str = "spline"):
    robot = robots.load("geering_2r")
    robot = dataclasses.replace(robot, limits=dataclasses.replace(robot.limits, **{k: np.array(v) for k, v in limits.items()}))
    path = WaypointPath(np.array(waypoints, dtype=float), interpolation)
    return plan(build_problem(robot, path, METHODS["phase_plane"], limits=LimitRequest(kinds=kinds)))


def test_a_stretch_that_moves_only_joints_without_a_limit_is_refused_naming_it():
    """phi limited, psi not: the straight segment on which psi alone moves has nothing to bound
    it; a spline through the same waypoints turns phi there too (it overshoots) and plans, and a
    torque limit on phi alone bounds psi through the inertia that couples them."""
    with pytest.raises(InvalidRequest) as refused:
        _planned({"velocity": [2.0, np.inf]}, ("velocity",), [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], "linear")
    assert (refused.value.rule, refused.value.joints) == ("stretch_unbounded", ("psi",))
    assert refused.value.s_from >= 0.5 and refused.value.s_to == pytest.approx(1.0, abs=0.02)
    assert detail(refused.value).startswith(f"from s = {refused.value.s_from:.4f} to {refused.value.s_to:.4f} nothing bounds the motion: joint 'psi' moves")
    assert _planned({"velocity": [2.0, np.inf]}, ("velocity",), [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]).duration > 0.5
    assert _planned({"torque": [25.0, np.inf]}, ("torque",), [[0.0, 0.0], [0.0, 1.0]]).duration > 0.1


def test_a_time_law_fits_a_stretch_that_a_limit_anywhere_on_it_bounds():
    """A time law takes one duration for the whole stretch between corners: where psi alone moves
    on a blend path, phi's limit elsewhere on the stretch still bounds it (the phase plane, point
    by point, is refused there)."""
    limits, waypoints = {"velocity": [2.0, np.inf]}, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]
    robot = robots.load("geering_2r")
    robot = dataclasses.replace(robot, limits=dataclasses.replace(robot.limits, velocity=np.array(limits["velocity"])))
    path = WaypointPath(np.array(waypoints), "blend")
    for law in ("quintic", "cycloidal"):
        assert plan(build_problem(robot, path, METHODS[law], limits=LimitRequest(kinds=("velocity",)))).duration > 1.0
    with pytest.raises(InvalidRequest, match="nothing bounds the motion|no limit held"):
        plan(build_problem(robot, path, METHODS["phase_plane"], limits=LimitRequest(kinds=("velocity",))))


def test_a_tool_speed_that_holds_only_where_it_can_is_no_bound_elsewhere(client):
    """A zone's tool speed bounds its zone only, and an angular speed limit nothing where the
    tool does not turn: both were divisions by zero in the timing."""
    zone = _trajectory(["velocity"]) | {}
    zone["timing"] = zone["timing"] | {"zones": [{"s_range": [0.4, 0.6], "tool_speed": 0.5}]}
    refused = client.post("/v1/trajectories", json=zone)
    assert refused.status_code == 422 and refused.json()["detail"].startswith("nothing bounds the motion of geering_2r"), refused.text
    turning = _trajectory(["velocity"])
    turning["path"]["waypoints"] = [[0.0, 0.0], [1.0, -1.0]]  # the hand's orientation phi + psi never changes
    turning["timing"]["limits"] = {"tool_angular_speed": 1.0}
    refused = client.post("/v1/trajectories", json=turning)
    assert refused.status_code == 422, refused.text
    assert refused.json()["detail"].startswith("from s = 0.0000 to 1.0000 nothing bounds the motion: joints 'phi', 'psi' move"), refused.text


def test_a_cell_arm_moving_only_a_joint_without_a_limit_is_refused_naming_the_arm():
    """A library caller's cell: geering_2r with a velocity limit on phi only, its first arm
    moving psi alone under the velocity limits. It was timed alone in 0.2 ms (nothing bounds
    psi) and the cell answered; it is refused naming the arm, the stretch and the joint."""
    from toptraj.planners.coordination import Cell, CellArm, coordinate
    from toptraj.planners.problem.waypoints import make_path
    from toptraj.robots.equipment import equip, mounting

    bare = robots.load("geering_2r")
    limited = dataclasses.replace(bare, limits=dataclasses.replace(bare.limits, velocity=np.array([2.0, np.inf])))

    def arm(waypoints, x):
        robot = equip(limited, None, mounting([x, 0.0, 0.0]))
        return CellArm(robot, make_path(robot, WaypointPath(np.array(waypoints, dtype=float))), robot.limits)

    moving_psi = Cell((arm([[0.0, 0.0], [0.0, 1.0]], 0.0), arm([[0.0, 0.0], [1.0, 0.0]], 5.0)), 0.01, ("velocity",))
    with pytest.raises(InvalidRequest) as refused:
        coordinate(moving_psi)
    assert refused.value.field == "arms[0]" and refused.value.rule == "stretch_unbounded"
    assert detail(refused.value).startswith(
        "arms[0]: from s = 0.0000 to 1.0000 nothing bounds the motion: joint 'psi' moves there without a finite velocity limit"
    ), detail(refused.value)
    # both arms turning phi, which has its limit: planned, the slower arm at 1 rad / 2 rad/s
    planned = coordinate(Cell((arm([[0.0, 0.0], [1.0, 0.0]], 0.0), arm([[0.0, 0.0], [0.5, 0.0]], 5.0)), 0.01, ("velocity",)))
    assert planned.solo[0] == pytest.approx(0.5, rel=0.02)


def test_a_cell_arm_is_advised_only_the_kinds_a_cell_holds():
    """An arm whose moving joint has a jerk limit but no velocity one: a cell holds no jerk, so
    the advice names torque (which the cell's constraints take), not jerk, and no tool speed."""
    from toptraj.planners.coordination import Cell, CellArm, coordinate
    from toptraj.planners.problem.waypoints import make_path
    from toptraj.robots.equipment import equip, mounting

    bare = robots.load("geering_2r")
    limits = dataclasses.replace(bare.limits, velocity=np.array([2.0, np.inf]), jerk=np.array([np.inf, 100.0]))
    limited = dataclasses.replace(bare, limits=limits)

    def arm(waypoints, x):
        robot = equip(limited, None, mounting([x, 0.0, 0.0]))
        return CellArm(robot, make_path(robot, WaypointPath(np.array(waypoints, dtype=float))), robot.limits)

    with pytest.raises(InvalidRequest) as refused:
        coordinate(Cell((arm([[0.0, 0.0], [0.0, 1.0]], 0.0), arm([[0.0, 0.0], [1.0, 0.0]], 5.0)), 0.01, ("velocity",)))
    text = detail(refused.value)
    assert "add 'torque' to constraints" in text and "jerk" not in text and "tool-speed" not in text, text
