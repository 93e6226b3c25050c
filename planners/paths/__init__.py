"""Geometric paths q(s), s in [0, 1]."""

from planners.paths.base import GeometricPath, PathPoints
from planners.paths.waypoints import SplinePath, StopAndGoPath, chord_knots

__all__ = ["GeometricPath", "PathPoints", "SplinePath", "StopAndGoPath", "chord_knots"]
