"""The service's words for the refusals of ``timing.zones`` that its schema cannot see (a box's
orientation that is not a unit quaternion, regions entered too often, a method that does not hold
zones), as ``toptraj.service.wordings`` words the other errors (``ZONE_WORDING`` is part of its
``WORDING``)."""

from __future__ import annotations

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
    "zone_kind_not_held": (
        "timing.zones[{index}].{kind}_scale scales the {kind} limit, which timing.constraints does not hold: add "
        "'{kind}' to timing.constraints, or leave timing.zones[{index}].{kind}_scale out"
    ),
    "zones_not_served": lambda facts: (
        f"timing.zones are held by timing.method {' or '.join(facts['methods'])} along a given path (path.kind "
        f"'waypoints' with interpolation 'spline', 'linear' or 'blend', or 'cartesian'), not by {facts['method']!r} "
        "here: choose one of those methods, or leave timing.zones out"
    ),
}
