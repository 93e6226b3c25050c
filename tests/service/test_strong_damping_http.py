"""A joint with strong viscous damping: phase_plane, toppra and min_cost time the path (their
tangent of D sqrt(x), taken first at the frictionless maximum velocity curve, asked torque no
slow motion needs, and they refused the path, "not even at rest"), and the torques of the
answer, recomputed independently (pinocchio's RNEA plus D qd + F sign(qd)), stay within the
effort limit."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

EFFORT = 9.0
WAYPOINTS = [[0.0, -1.0, 1.0], [1.0, 0.5, -0.8], [-0.5, 1.2, 0.4]]


def _urdf(damping: float, friction: float = 2.0) -> str:
    inertial = (
        '<inertial><origin xyz="0 0 0.25"/><mass value="1"/>'
        '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.002"/></inertial>'
    )
    joints = []
    for index, (parent, axis, height) in enumerate((("base", "0 0 1", 0.1), ("l1", "0 1 0", 0.5), ("l2", "0 1 0", 0.5)), start=1):
        joints.append(
            f'<link name="l{index}">{inertial}</link><joint name="j{index}" type="revolute"><parent link="{parent}"/>'
            f'<child link="l{index}"/><origin xyz="0 0 {height}"/><axis xyz="{axis}"/>'
            f'<limit effort="{EFFORT}" velocity="2" lower="-2" upper="2"/><dynamics damping="{damping}" friction="{friction}"/></joint>'
        )
    return '<robot name="damped"><link name="base"/>' + "".join(joints) + "</robot>"


@pytest.mark.parametrize("method", ["phase_plane", "toppra", "min_cost"])
@pytest.mark.parametrize("damping", [3.0, 10.0])
def test_strong_damping_is_timed_within_the_effort(client, damping, method):
    urdf = _urdf(damping)
    name = f"damped_{int(damping)}"
    assert client.post("/v1/robots", json={"name": name, "urdf": urdf}).status_code in (200, 201)
    answer = client.post("/v1/trajectories", json={
        "robot": name, "path": {"kind": "waypoints", "interpolation": "spline", "waypoints": WAYPOINTS},
        "timing": {"method": method, "constraints": ["velocity", "acceleration", "torque"]}, "output": {"dt": 0.01},
    })
    assert answer.status_code == 200, answer.text
    samples = answer.json()["samples"]
    q, qd, qdd, tau = (np.asarray(samples[key]) for key in ("q", "qd", "qdd", "tau"))
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    moving = np.abs(qd) > 1e-9
    independent = np.array([pin.rnea(model, data, *row) for row in zip(q, qd, qdd)]) + damping * qd + 2.0 * np.sign(qd)
    assert np.abs(independent[moving.all(axis=1)]).max() <= EFFORT * 1.005
    assert np.allclose(independent[moving.all(axis=1)], tau[moving.all(axis=1)], atol=1e-6 * EFFORT)
    if method != "min_cost":  # a time-optimal motion is not slowed beyond need: a torque reaches its limit
        assert np.abs(tau).max() >= EFFORT * 0.999


def test_a_refusal_under_damping_states_the_first_tangents_numbers():
    """A path no reference of the damping's tangent lets through (a start faster than the path
    allows) is refused with the numbers of the first tangent, at the speed limit: the lowest one
    tried, at 1/65536 of it, understates the speeds allowed ninefold."""
    from toptraj.planners.constraints.path_constraints import build_path_constraints
    from toptraj.planners.errors import InfeasiblePath
    from toptraj.planners.paths import SplinePath
    from toptraj.planners.paths.grid import path_grid
    from toptraj.planners.timing.base import Boundary
    from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
    from toptraj.planners.timing.toppra_method import ToppraMethod
    from toptraj.robots.upload_options import UploadOptions
    from toptraj.robots.uploads import build_upload

    robot = build_upload("damped", _urdf(0.5), UploadOptions())
    path = SplinePath(np.array(WAYPOINTS))
    constraints = build_path_constraints(path, robot, robot.limits, ("velocity", "acceleration", "torque"), path_grid(path))
    for method in (PhasePlaneMethod(), ToppraMethod()):
        with pytest.raises(InfeasiblePath, match=r"0\.408814"):
            method.solve(constraints, Boundary(sd_start=0.5))
