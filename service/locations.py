"""Where in a request body something is, as the service writes it: ``timing.zones[0].s_range``
(dots between fields, list indices in brackets, pydantic's union tags left out). The HTTP 422s
(``toptraj.service.errors``), the CLI's and the batches' (``toptraj.service.problems``) and the
refusal of a key given twice (``toptraj.service.strict_json``) all write places this way."""

from __future__ import annotations

from collections.abc import Iterable

#: Tags of the path union that pydantic puts in error locations: path.<tag>.<field>.
_PATH_TAGS = ("waypoints", "cartesian", "free")
#: Tags of the payload's inertia (6 values or a matrix): payload.inertia.<tag>[i].
_INERTIA_TAGS = ("values", "matrix")
#: Tags of an obstacle (its kind): obstacles[i].<tag>.<field>.
_OBSTACLE_TAGS = ("sphere", "box", "capsule")


def _is_tag(parts: list[str], index: int) -> bool:
    """Whether ``parts[index]`` is the tag of a union member that pydantic puts in a location,
    not a field of the request."""
    before, part = parts[:index], parts[index]
    if before[-1:] == ["path"]:
        return part in _PATH_TAGS and index + 1 < len(parts)  # path.<tag>.<field>, at the top or in a job
    if before[-1:] == ["inertia"]:
        return part in _INERTIA_TAGS
    return before[-2:-1] == ["obstacles"] and before[-1].isdigit() and part in _OBSTACLE_TAGS


def joined(parts: Iterable[str | int]) -> str:
    """``parts`` (field names and list indices) written as one place: ``timing.zones[0]``;
    ``body`` for the body itself."""
    text = ""
    for part in parts:
        text += f"[{part}]" if isinstance(part, int) or part.isdigit() else (f".{part}" if text else part)
    return text or "body"


def where(loc: Iterable[str | int]) -> str:
    """A pydantic error location (``("body", "timing", "zones", 0)``) as the service writes it
    (``timing.zones[0]``): without ``body`` and the union tags."""
    parts = [str(part) for part in loc if part != "body"]
    return joined(part for index, part in enumerate(parts) if not _is_tag(parts, index))
