"""The service's words for a path or an end too close to an obstacle (``path.obstacles``), with
the advice that lets it through, as ``toptraj.service.wordings`` words the other errors
(``OBSTACLE_WORDING`` is part of its ``WORDING``)."""

from __future__ import annotations

import math
from collections.abc import Callable


def _below(distance: float, clearance: float) -> str:
    """``distance`` (m, below ``clearance``) to four significant digits, or as many more as
    tell it from the clearance (0.029996 m, not 0.03 m, under a clearance of 0.03 m)."""
    for digits in range(4, 18):
        text = f"{distance:.{digits}g}"
        if float(text) < clearance:
            return text
    return text


def _path_in_collision(facts: dict) -> str:
    index, distance = facts["obstacle"], facts["distance"]
    within = _below(distance, facts["clearance"])
    how = f"is inside path.obstacles[{index}] (by {-distance:.4g} m)" if distance < 0 else f"comes within {within} m of path.obstacles[{index}]"
    closest = "" if facts["closest"] is None else f"; the closest approach is {facts['closest'][0]:.4g} m at s = {facts['closest'][1]:.4g}"
    if facts.get("fixed"):
        advice = f"no joint moves that link: move path.obstacles[{index}] away from it, or the robot by its mounting"
    else:
        advice = "move the waypoints away from the obstacle"
    least = facts.get("least", -1.0)  # a lower bound on the path's distance, good to about half a millimetre
    if least > 0.0:  # advised 0.1 mm down (0 m at worst): a clearance the check then confirms
        advice += f"{',' if facts.get('fixed') else ''} or lower path.clearance to {math.floor(1e4 * least) / 1e4:g} m"
    elif "least_s" in facts and not facts.get("fixed"):
        advice += f" (near s = {facts['least_s']:.4g} the path touches an obstacle, or comes within about half a millimetre of one)"
    return f"link {facts['link']!r} {how} at s = {facts['s']:.4g} (the clearance is {facts['clearance']:g} m{closest}): {advice}"


def _end_too_close(facts: dict) -> str:
    """A free path's start or goal within the clearance of an obstacle; a link no joint moves is
    advised to move the obstacle or the robot, since no start or goal moves it."""
    field, index, distance = facts["field"], facts["obstacle"], facts["distance"]
    within = _below(distance, facts["clearance"])
    how = f"is inside path.obstacles[{index}] (by {-distance:.4g} m)" if distance < 0 else f"comes within {within} m of path.obstacles[{index}]"
    if facts.get("fixed"):
        advice = f"no joint moves that link: move path.obstacles[{index}] away from it, or the robot by its mounting"
    else:
        advice = f"move {field} away from the obstacle"
    below = math.floor(1e4 * distance) / 1e4  # the end's distance, 0.1 mm down
    if below > 0.0:
        advice += f"{',' if facts.get('fixed') else ''} or lower path.clearance to {below:g} m"
    return f"at {field}, link {facts['link']!r} {how} (the clearance is {facts['clearance']:g} m): {advice}"


OBSTACLE_WORDING: dict[str, str | Callable[[dict], str]] = {
    "path_in_collision": _path_in_collision,
    "end_too_close": _end_too_close,
}
