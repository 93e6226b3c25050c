"""Free-path motions: the path and its timing optimized together from start to goal."""

from toptraj.planners.generators.collocation.collocation import collocation_path, optimize_motion
from toptraj.planners.generators.collocation.motion import CollocationResult, FreeMotion

__all__ = ["CollocationResult", "FreeMotion", "collocation_path", "optimize_motion"]
