"""Robots by name: the catalog first, then the uploads (``robots.load``, public contract)."""

from __future__ import annotations

from toptraj.robots.catalog import catalog_names, is_catalog_robot, load_catalog_robot
from toptraj.robots.errors import UnknownRobot
from toptraj.robots.robot import Robot


def load(name: str) -> Robot:
    """The robot called ``name``: a catalog robot (built once per process) or an upload (read
    from the store, its model kept in a bounded cache).

    Raises:
        UnknownRobot: no bundled, example-robot-data or uploaded robot has that name.
    """
    if is_catalog_robot(name):
        return load_catalog_robot(name)
    from toptraj.robots.uploads import load_upload  # the store and its SQLite: uploads only

    robot = load_upload(name)
    if robot is None:
        raise UnknownRobot(name, catalog_names())
    return robot
