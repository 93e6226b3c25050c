"""Geometric paths q(s), s in [0, 1]."""

from toptraj.planners.paths.base import GeometricPath, PathPoints
from toptraj.planners.paths.waypoints import SplinePath, StopAndGoPath, chord_knots

__all__ = ["GeometricPath", "PathPoints", "SplinePath", "StopAndGoPath", "chord_knots"]
