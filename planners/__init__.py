"""Planners: geometric paths, path constraints, timing methods and trajectory sampling."""

from toptraj.planners.constraints.path_constraints import PathConstraints, build_path_constraints
from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, InvalidRequest, TimingFailed
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.plan import plan
from toptraj.planners.problem.requests import Timing, WaypointPath
from toptraj.planners.results import PlannedTrajectory
from toptraj.planners.timing import METHODS, TimeScaling

__all__ = [
    "METHODS",
    "BudgetExceeded",
    "CartesianLine",
    "Deadline",
    "InfeasiblePath",
    "InvalidRequest",
    "PathConstraints",
    "PlannedTrajectory",
    "TimeScaling",
    "Timing",
    "TimingFailed",
    "WaypointPath",
    "build_path_constraints",
    "plan",
]
