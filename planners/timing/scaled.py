"""Solving a timing problem in a scaled time, for solvers with absolute tolerances.

A stretch of path that spans a tiny part of joint space (a 1e-6 rad step of a stop-and-go path)
has path speeds sd of 1e6 and more in its own parameter: an LP or conic solver with absolute
tolerances then fails on a problem that is perfectly feasible. With x = kappa x' and
u = kappa u' the problem keeps its form (``PathConstraints.time_scaled``); solved in x' of order
one, the answer is mapped back by sd = sqrt(kappa) sd' (and a cost that is an integral over time
by dt = dt' / sqrt(kappa)).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.constraints.admissible import speed_scale
from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.timing.base import Boundary, PathTiming, TimeScaling, TimingMethod

#: Typical x within this factor of 1 is solved as it is.
_WELL_SCALED = 1e2


def solve_well_scaled(
    method: TimingMethod,
    constraints: PathConstraints,
    boundary: Boundary,
    duration: float | None,
    deadline: Deadline,
) -> PathTiming:
    """``method.solve`` on ``constraints``, in a scaled time when the method needs numbers of
    order one (``TimingMethod.absolute_tolerances``) and the path's typical x is far from 1."""
    kappa = speed_scale(constraints) if method.absolute_tolerances else 1.0
    if 1.0 / _WELL_SCALED <= kappa <= _WELL_SCALED:
        return method.solve(constraints, boundary, duration, deadline)
    root = np.sqrt(kappa)
    scaled_boundary = Boundary(
        sd_start=boundary.sd_start / root,
        sd_end=boundary.sd_end / root,
        sdd_start=None if boundary.sdd_start is None else boundary.sdd_start / kappa,
        sdd_end=None if boundary.sdd_end is None else boundary.sdd_end / kappa,
    )
    result = method.solve(constraints.time_scaled(kappa), scaled_boundary, duration, deadline)
    assert isinstance(result, TimeScaling)
    changes = {"sd": result.sd * root}
    if hasattr(result, "cost"):
        changes["cost"] = result.cost / root
    return dataclasses.replace(result, **changes)
