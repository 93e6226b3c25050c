"""Free-path motions: the path and its timing optimized together from start to goal."""

from toptraj.planners.generators.collocation.collocation import optimize_motion
from toptraj.planners.generators.collocation.motion import CollocationResult, collocation_path

__all__ = ["CollocationResult", "collocation_path", "optimize_motion"]
