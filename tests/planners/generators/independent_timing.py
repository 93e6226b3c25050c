"""An independent time-optimal duration of a path, for references the search's own timing is
checked against: TOPP-RA through the ``toppra`` package's public API (Pham & Pham, IEEE T-RO
2018) with its own torque constraint on Pinocchio's ``rnea`` (at the robot's configuration of
the joint coordinates; toppra derives the constraint's coefficients itself), on a dense uniform
grid, at rest at both ends. Neither the project's constraint rows nor its phase-plane
integration take part."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from toptraj.planners.paths.base import GeometricPath


def toppra_torque_duration(robot, path: GeometricPath, intervals: int) -> float:
    """The duration (s) of the time-optimal motion along ``path`` (s in [0, 1], q in joint
    units) under ``robot``'s torque limits only, by TOPP-RA on ``intervals`` uniform intervals:
    the sum over intervals of 2 ds / (sd_i + sd_i+1) (constant path acceleration in each)."""
    import toppra
    import toppra.algorithm
    import toppra.constraint
    from toppra.interpolator import AbstractGeometricPath

    class _Path(AbstractGeometricPath):
        def __call__(self, s, order=0):
            points = path.evaluate(np.atleast_1d(np.asarray(s, dtype=float)))
            values = (points.q, points.dq, points.ddq)[order]
            return values if np.ndim(s) else values[0]

        @property
        def dof(self):
            return robot.dof

        @property
        def path_interval(self):
            return np.array([0.0, 1.0])

        @property
        def waypoints(self):
            return np.linspace(0.0, 1.0, 2)

    model, data = robot.model, robot.model.createData()
    torque = np.column_stack([-robot.limits.torque, robot.limits.torque])
    constraint = toppra.constraint.JointTorqueConstraint(
        lambda q, qd, qdd: pin.rnea(model, data, robot.configuration(q), qd, qdd), torque, np.zeros(robot.dof)
    )
    s = np.linspace(0.0, 1.0, intervals + 1)
    solver = toppra.algorithm.TOPPRA([constraint], _Path(), gridpoints=s, solver_wrapper="seidel")
    _, sd, _ = solver.compute_parameterization(0.0, 0.0)
    if sd is None:
        raise ValueError("toppra found no timing along the path")
    sd = np.asarray(sd, dtype=float)
    return float(np.sum(2.0 * np.diff(s) / (sd[:-1] + sd[1:])))
