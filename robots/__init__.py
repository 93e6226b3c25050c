"""Robots: the catalog (bundled paper arms, example-robot-data arms, uploads) and ``Robot``."""

from robots.catalog import catalog_names, load, register_urdf
from robots.errors import InvalidLimits, InvalidURDF, RobotConflict, ToptrajError, UnknownRobot
from robots.limits import LIMIT_KINDS, JointLimits
from robots.robot import Robot

__all__ = [
    "LIMIT_KINDS",
    "InvalidLimits",
    "InvalidURDF",
    "JointLimits",
    "Robot",
    "RobotConflict",
    "ToptrajError",
    "UnknownRobot",
    "catalog_names",
    "load",
    "register_urdf",
]
