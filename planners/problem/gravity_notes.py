"""A gravity given with a robot's mounting that looks mistyped: pointing up, or of a magnitude
far from the Earth's. The torques follow the gravity given, so the answer is right for it, but
[0, 0, 9.81] for [0, 0, -9.81] (the sign) or 98.1 for 9.81 would otherwise be planned under
without a word; a ceiling mount turns the base (``orientation``), not the gravity."""

from __future__ import annotations

import numpy as np

from toptraj.robots import Robot
from toptraj.robots.notes import Note

#: The standard gravity (m/s^2) and the band of magnitudes taken for the Earth's.
EARTH = 9.80665
EARTH_BAND = (9.7, 9.9)


def gravity_notes(robot: Robot) -> tuple[Note, ...]:
    """A note when the gravity of ``robot``'s mounting (given, not the model's own) points up
    (+z in the world) or has a magnitude outside ``EARTH_BAND`` other than 0 (none at all)."""
    mounting = robot.mounting
    if mounting is None or mounting.gravity is None:
        return ()
    gravity = np.asarray(mounting.gravity, dtype=float)
    magnitude = float(np.linalg.norm(gravity))
    if magnitude == 0.0:
        return ()
    up = gravity[2] > 0.5 * magnitude
    odd = not EARTH_BAND[0] <= magnitude <= EARTH_BAND[1]
    if not (up or odd):
        return ()
    why = "points up (+z in the world)" if up else f"has a magnitude of {magnitude:.4g} m/s^2 (the Earth's is {EARTH:g})"
    return (Note(
        f"mounting.gravity {gravity.tolist()} {why}: the torques follow it",
        "gravity_unusual", field="mounting.gravity", gravity=tuple(gravity.tolist()), up=bool(up), magnitude=magnitude,
    ),)
