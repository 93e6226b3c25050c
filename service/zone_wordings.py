"""The service's words for the refusals of ``timing.zones`` that its schema cannot see (a box's
orientation that is not a unit quaternion, regions entered too often, a method that does not hold
zones), as ``toptraj.service.wordings`` words the other errors (``ZONE_WORDING`` is part of its
``WORDING``)."""

from __future__ import annotations

import json
from collections.abc import Callable

ZONE_WORDING: dict[str, str | Callable[[dict], str]] = {
    "zone_box_not_unit": (
        "timing.zones[{index}].box.orientation has norm {norm:.6g}: it is no rotation; give a unit quaternion "
        "[qx, qy, qz, qw] (norm 1 within {tolerance:g}), e.g. [0, 0, 0, 1] for a box along the world's axes"
    ),
    "zone_ranges_too_many": (
        "timing.zones cover more than {most} stretches of the path from timing.zones[{index}] on: the tool point "
        "enters and leaves a region many times; give fewer or larger regions, or an s_range instead"
    ),
    "zone_kind_not_held": lambda facts: (
        f"timing.zones[{facts['index']}].{facts['kind']}_scale scales the {facts['kind']} limit, which is not among the "
        f"limits held ({', '.join(facts['kinds_held'])}): give timing.constraints with {facts['kind']!r} among them "
        f"({json.dumps([*facts['kinds_held'], facts['kind']])}), or leave timing.zones[{facts['index']}].{facts['kind']}_scale out"
    ),
    "zones_not_served": lambda facts: (
        f"timing.zones are held by timing.method {' or '.join(facts['methods'])} along a given path (path.kind "
        f"'waypoints' with interpolation 'spline', 'linear' or 'blend', or 'cartesian'), not by {facts['method']!r} "
        "here: choose one of those methods, or leave timing.zones out"
    ),
}
