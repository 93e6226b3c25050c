"""Planners: geometric paths, path constraints, timing methods and trajectory sampling."""

from planners.constraints.path_constraints import PathConstraints, build_path_constraints
from planners.errors import BudgetExceeded, InfeasiblePath, InvalidRequest, TimingFailed
from planners.execution.deadline import Deadline
from planners.paths.cartesian import CartesianLine
from planners.plan import plan
from planners.problem.requests import Timing, WaypointPath
from planners.results import PlannedTrajectory
from planners.timing import METHODS, TimeScaling

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
