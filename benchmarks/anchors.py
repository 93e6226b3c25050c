"""The anchors our timings are measured against, each as its own users call it: toppra through
its public API (``SplineInterpolator``, its joint constraints with a Pinocchio RNEA callback,
``TOPPRA``) and Drake's ``Toppra`` on a ``MultibodyPlant`` of the same URDF (only when
``pydrake`` imports: ``pip install toptraj[bench]``; never a dependency of the service).

``bare_toppra`` and ``drake_solver`` solve the typical request's path (``end_to_end.py``);
``toppra_runner``, ``drake_plant`` and ``drake_runner`` time the random paths of
``phase_plane_vs_toppra.py`` on any grid.
"""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin

from toptraj import robots
from toptraj.planners.errors import TimingFailed
from toptraj.planners.paths.grid import path_grid


def typical_spline(waypoints: np.ndarray):
    """toppra's ``SplineInterpolator`` of the path the service builds from ``waypoints``
    (n_waypoints, n_dof): knots at chord-length values of s in [0, 1] (cumulative joint distance
    over its total) and natural ends (zero second derivative), as ``SplinePath``."""
    import toppra

    lengths = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    knots = np.concatenate(([0.0], np.cumsum(lengths))) / lengths.sum()
    return toppra.SplineInterpolator(knots, waypoints, bc_type="natural")


def bare_toppra(robot: robots.Robot, waypoints: np.ndarray, intervals: int = 100) -> float:
    """One toppra solve through its public API along the service's spline (``typical_spline``)
    on ``intervals`` evenly spaced grid intervals (the service chooses its own grid); returns
    the duration (s)."""
    import toppra

    model, data, limits = robot.model, robot.model.createData(), robot.limits
    path = typical_spline(waypoints)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-limits.velocity, limits.velocity])),
        toppra.constraint.JointAccelerationConstraint(np.column_stack([-limits.acceleration, limits.acceleration])),
        toppra.constraint.JointTorqueConstraint(
            lambda q, qd, qdd: pin.rnea(model, data, q, qd, qdd),
            np.column_stack([-limits.torque, limits.torque]),
            np.zeros(robot.dof),
        ),
    ]
    solver = toppra.algorithm.TOPPRA(
        constraints, path, gridpoints=np.linspace(0.0, 1.0, intervals + 1), parametrizer="ParametrizeConstAccel"
    )
    return float(solver.compute_trajectory().duration)


def drake_solver(robot: robots.Robot, waypoints: np.ndarray, intervals: int = 100):
    """One solve of Drake's Toppra on the cubic Hermite interpolation of the service's spline
    through ``waypoints`` (``typical_spline``, the bare toppra probe's path) and the robot's limits, as a function returning the duration (s); ``None``
    when pydrake is absent. The plant and the spline are built here, once."""
    plant = drake_plant(robot)
    if plant is None:
        return None
    from pydrake.multibody.optimization import Toppra
    from pydrake.trajectories import PiecewisePolynomial

    path = typical_spline(waypoints)
    knots = path.ss_waypoints
    slopes = path(knots, 1)
    spline = PiecewisePolynomial.CubicHermite(knots, waypoints.T, slopes.T)
    grid, limits = np.linspace(0.0, 1.0, intervals + 1), robot.limits

    def solve() -> float:
        problem = Toppra(spline, plant, grid)
        problem.AddJointVelocityLimit(-limits.velocity, limits.velocity)
        problem.AddJointAccelerationLimit(-limits.acceleration, limits.acceleration)
        problem.AddJointTorqueLimit(-limits.torque, limits.torque)
        result = problem.SolvePathParameterization()
        if result is None:
            raise RuntimeError("Drake's Toppra failed on the typical path")
        return float(result.end_time())

    return solve


def toppra_runner(robot, waypoints, path, now, interpolation: bool = False):
    """(total, nan, duration, "", nan) of toppra through its public API at n intervals, times in s
    by the clock ``now``, with its
    default discretizations or (``interpolation``) the interpolation one for torque too. Limits
    that are infinite (the two-link arms have only torque limits) are left out, as a toppra
    user would."""
    import toppra
    import toppra.algorithm
    import toppra.constraint

    model = robot.model
    data = model.createData()
    damping = robot.viscous_friction
    to_configuration = robot.configuration if np.any(robot.continuous) else (lambda q: q)

    def inverse_dynamics(q, v, a):
        return pin.rnea(model, data, to_configuration(q), v, a) + damping * v

    spline = toppra.SplineInterpolator(path.knots, waypoints, bc_type="natural")
    limits = robot.limits

    def constraints():
        made = []
        if np.all(np.isfinite(limits.velocity)):
            made.append(toppra.constraint.JointVelocityConstraint(np.column_stack([-limits.velocity, limits.velocity])))
        if np.all(np.isfinite(limits.acceleration)):
            made.append(
                toppra.constraint.JointAccelerationConstraint(np.column_stack([-limits.acceleration, limits.acceleration]))
            )
        scheme = toppra.constraint.DiscretizationType.Interpolation if interpolation else toppra.constraint.DiscretizationType.Collocation
        made.append(
            toppra.constraint.JointTorqueConstraint(
                inverse_dynamics, np.column_stack([-limits.torque, limits.torque]), robot.coulomb_friction, scheme
            )
        )
        return made

    def run(n):
        grid = path_grid(path, n)
        started = now()
        instance = toppra.algorithm.TOPPRA(constraints(), spline, gridpoints=grid, solver_wrapper="seidel")
        _, sd, _ = instance.compute_parameterization(0.0, 0.0)
        done = now()
        if sd is None:
            raise TimingFailed("toppra found no parameterization")
        return done - started, np.nan, float(np.sum(2.0 * np.diff(grid) / (sd[1:] + sd[:-1]))), "", np.nan

    return run


def drake_plant(robot):
    """Drake's MultibodyPlant of ``robot``'s URDF without visual and collision elements (their
    meshes are package:// URIs), or ``None`` when pydrake is absent."""
    try:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant
    except ImportError:
        return None
    from toptraj.robots.catalog import EXAMPLE_ARMS, example_urdf_path

    with open(example_urdf_path(EXAMPLE_ARMS[robot.name].loader)) as handle:
        text = re.sub(r"<(visual|collision)\b.*?</\1>", "", handle.read(), flags=re.S)
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(text, "urdf")
    if 'name="world"' not in text:
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(plant.GetBodyByName(robot.model.names[1]).name()))
    plant.Finalize()
    names = tuple(plant.get_joint(index).name() for index in plant.GetJointIndices() if plant.get_joint(index).num_positions() == 1)
    if names[: robot.dof] != robot.joint_names:
        raise RuntimeError(f"Drake's joint order {names} differs from Pinocchio's {robot.joint_names}")
    return plant


def drake_runner(plant, robot, waypoints, path, now, failures: list):
    """(total, nan, duration, "", nan) of Drake's Toppra at n intervals, times in s by the clock
    ``now``; grids where it fails are appended to ``failures``."""
    from pydrake.multibody.optimization import Toppra
    from pydrake.trajectories import PiecewisePolynomial

    # Cubic Hermite through the knots with the spline's own slopes: the same cubic per segment.
    spline = PiecewisePolynomial.CubicHermite(path.knots, waypoints.T, path.evaluate(path.knots).dq.T)
    limits = robot.limits

    def run(n):
        grid = path_grid(path, n)
        started = now()
        toppra = Toppra(spline, plant, grid)
        toppra.AddJointVelocityLimit(-limits.velocity, limits.velocity)
        toppra.AddJointAccelerationLimit(-limits.acceleration, limits.acceleration)
        toppra.AddJointTorqueLimit(-limits.torque, limits.torque)
        result = toppra.SolvePathParameterization()
        done = now()
        if result is None:
            failures.append(n)
            raise TimingFailed("Drake's Toppra failed")
        return done - started, np.nan, float(result.end_time()), "", np.nan

    return run
