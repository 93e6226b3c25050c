"""Planners: geometric paths, path constraints, timing methods and trajectory sampling."""

from toptraj.planners.constraints.path_constraints import PathConstraints, build_path_constraints
from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, InvalidRequest, TimingFailed
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.paths.cartesian import CartesianLine
from toptraj.planners.plan import plan
from toptraj.planners.problem.build import build_problem
from toptraj.planners.problem.problem import BoundaryStates, LimitRequest, Sampling
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.time_law import TimeLaw
from toptraj.planners.results import PlannedTrajectory
from toptraj.planners.timing import METHODS, TimeScaling

__all__ = [
    "METHODS",
    "BoundaryStates",
    "BudgetExceeded",
    "CartesianLine",
    "Deadline",
    "InfeasiblePath",
    "InvalidRequest",
    "LimitRequest",
    "PathConstraints",
    "PlannedTrajectory",
    "Sampling",
    "TimeLaw",
    "TimeScaling",
    "TimingFailed",
    "WaypointPath",
    "build_path_constraints",
    "build_problem",
    "plan",
]
