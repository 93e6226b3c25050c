"""Free-path motions: the path and its timing optimized together from start to goal."""

from planners.free_path.collocation import CollocationResult, FreeMotion, collocation_path, optimize_motion

__all__ = ["CollocationResult", "FreeMotion", "collocation_path", "optimize_motion"]
