"""Where a field put in the wrong place belongs: for a field a schema does not know
(pydantic's ``extra_forbidden``), the places a field of that name has in the body's schema, so
that the 422 can say where to move it (``format`` at the top of a trajectory request belongs in
``output.format``)."""

from __future__ import annotations

import functools
import re
import typing
from collections.abc import Iterator

from pydantic import BaseModel

#: Deepest nesting of request models walked (the request schemas nest five levels at most).
MAX_DEPTH = 8
#: Most places named in one hint.
MAX_PLACES = 3


def _models(annotation: object, listed: bool = False) -> Iterator[tuple[type[BaseModel], bool]]:
    """The request models inside ``annotation`` (through Optional, unions, Annotated, lists and
    tuples), each with whether it sits in a list."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        yield annotation, listed
        return
    inner_listed = listed or typing.get_origin(annotation) in (list, tuple)
    for argument in typing.get_args(annotation):
        yield from _models(argument, inner_listed)


@functools.cache
def field_places(model: type[BaseModel]) -> dict[str, tuple[str, ...]]:
    """{field name: the dotted places of the fields of that name in ``model``}, lists written as
    ``[i]`` (``{"format": ("output.format",), …}``)."""
    places: dict[str, list[str]] = {}

    def walk(current: type[BaseModel], prefix: str, depth: int) -> None:
        if depth > MAX_DEPTH:
            return
        for name, info in current.model_fields.items():
            key = info.alias or name
            path = f"{prefix}.{key}" if prefix else key
            if path not in places.setdefault(key, []):
                places[key].append(path)
            for inner, listed in _models(info.annotation):
                walk(inner, f"{path}[i]" if listed else path, depth + 1)

    walk(model, "", 0)
    return {name: tuple(paths) for name, paths in places.items()}


def hint(model: type[BaseModel] | None, location: str) -> str:
    """Where the unknown field at ``location`` (as ``service.errors`` writes it: ``format``,
    ``path.waypoints[0].x``) belongs in ``model``, as a clause to add to pydantic's message; ""
    when the body's schema has no field of that name elsewhere."""
    if model is None:
        return ""
    name = location.rpartition(".")[2]
    if "[" in name:
        return ""
    here = re.sub(r"\[\d+\]", "[i]", location)
    places = [place for place in field_places(model).get(name, ()) if place != here][:MAX_PLACES]
    if not places:
        return ""
    return f": {name!r} belongs in " + " or ".join(places)

