"""Hints for a field a schema does not know (pydantic's ``extra_forbidden``): where a field put in
the wrong place belongs, the places a field of that name has in the body's schema, so that the 422
can say where to move it (``format`` at the top of a trajectory request belongs in
``output.format``); else the allowed name at that very place nearest to a misspelt one
(``velocity_scal``: did you mean 'velocity_scale'?)."""

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
#: Least similarity (difflib's ratio, 2 M / T) of an unknown name to an allowed one for "did you mean".
CLOSE = 0.75


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


def _tags(model: type[BaseModel]) -> set[str]:
    """The names pydantic may put in a location for ``model`` as a member of a union: its class
    name and the values of its ``Literal`` fields (a tagged union's tag: the path's ``kind``)."""
    tags = {model.__name__}
    for info in model.model_fields.values():
        if typing.get_origin(info.annotation) is typing.Literal:
            tags.update(str(value) for value in typing.get_args(info.annotation))
    return tags


#: Places whose allowed names are kept (``names_at``), per body model.
NAMES_KEPT = 256


def names_at(model: type[BaseModel], loc: tuple[str | int, ...]) -> tuple[str, ...]:
    """The field names a body of ``model`` allows at ``loc`` (a pydantic location relative to
    the body, union tags included: ``("path", "cartesian")``); () where ``loc`` leaves the
    request models (a dict's keys, a number). Kept per model and place (list indices aside:
    an item of a list has its models from its field), so that many errors at one place walk
    the schema once."""
    return _names_at(model, tuple(part for part in loc[:MAX_DEPTH] if not isinstance(part, int)))


@functools.lru_cache(maxsize=NAMES_KEPT)
def _names_at(model: type[BaseModel], place: tuple[str | int, ...]) -> tuple[str, ...]:
    """``names_at`` of ``place`` (keys only, at most ``MAX_DEPTH``)."""
    candidates = [model]
    for part in place:
        if len(candidates) > 1 and (tagged := [current for current in candidates if part in _tags(current)]):
            candidates = tagged
            continue
        candidates = [
            inner
            for current in candidates
            for name, info in current.model_fields.items()
            if (info.alias or name) == part
            for inner, _ in _models(info.annotation)
        ]
        if not candidates:
            return ()
    return tuple(dict.fromkeys(info.alias or name for current in candidates for name, info in current.model_fields.items()))


def nearest(model: type[BaseModel] | None, loc: tuple[str | int, ...]) -> str:
    """For the unknown field at ``loc``, the allowed name at its place most like it, as a clause
    to add to pydantic's message (``: did you mean 'velocity_scale'?``); "" when none is close
    (``CLOSE``)."""
    if model is None or not loc or not isinstance(loc[-1], str):
        return ""
    close = closest(loc[-1], names_at(model, loc[:-1]))
    return f": did you mean {close!r}?" if close else ""


def closest(given: str, allowed: typing.Iterable[str]) -> str | None:
    """The allowed name ``given`` was most likely meant as: the one equal to it but for case,
    else difflib's closest at ``CLOSE`` or more (``"URDF"`` -> ``"urdf"``, ``"topra"`` ->
    ``"toppra"``); None when none is close."""
    allowed = list(allowed)
    same = [name for name in allowed if name.casefold() == given.casefold()]
    if same:
        return same[0]
    import difflib  # here: only a refused name needs it

    close = difflib.get_close_matches(given, allowed, n=1, cutoff=CLOSE)
    return close[0] if close else None


#: Where a cell body (``arms``, each with its own path) goes.
CELL_ELSEWHERE = (
    ": a cell (several arms, each along its own path) is planned by POST /v1/cells or `toptraj plan FILE`, "
    "not by this route; its other fields (clearance, dt) belong to that body"
)
#: Fields of a trajectory request that a cell does not take.
_CELL_NO_ZONES = (
    ": a cell holds each arm's limits along its whole path (the arm's velocity_scale, acceleration_scale, "
    "torque_scale); limits on part of a path (timing.zones) are served for one arm by POST /v1/trajectories"
)
_CELL_NO_OBSTACLES = (
    ": a cell keeps its arms `clearance` apart from each other; obstacles are served for one arm by "
    "POST /v1/trajectories (path.obstacles)"
)
_CELL_SELF_COLLISION = ": a cell always checks each arm's links against each other; leave it out"
_CELL_TIMING = (
    ": a cell times its arms time-optimally under each arm's velocity, acceleration and torque limits; give "
    "velocity_scale, acceleration_scale or torque_scale on the arm itself"
)
#: What to do with a field that belongs to another route or to no body at all, by the body's
#: schema and the field's place ("*": any unknown field at the top of that schema).
ELSEWHERE = {
    ("TrajectoryRequest", "methods"): ": several methods are compared by POST /v1/trajectories/compare (same body with "
    "`methods`, no `output`); here give one method as timing.method",
    ("CompareRequest", "output"): ": a comparison answers each method's duration, peak utilization and solve time, "
    "without samples, so it takes no `output`; POST /v1/trajectories (one method, timing.method) returns the samples",
    ("CompareRequest", "method"): ": a comparison runs the list `methods` (e.g. [\"phase_plane\", \"quintic\"])",
    ("TrajectoryRequest", "arms"): CELL_ELSEWHERE,
    ("CompareRequest", "arms"): CELL_ELSEWHERE,
    ("JobCreate", "cell"): CELL_ELSEWHERE,
    ("JobCreate", "arms"): CELL_ELSEWHERE,
    ("CellArmRequest", "mounting"): ": a cell arm's pose in the world is its `base` ({\"position\": [x, y, z], "
    "\"orientation\": [qx, qy, qz, qw]} or a 3x3 \"rotation\"), and the world's gravity is the cell's `gravity`",
    ("CellRequest", "zones"): _CELL_NO_ZONES,
    ("CellArmRequest", "zones"): _CELL_NO_ZONES,
    ("CellRequest", "obstacles"): _CELL_NO_OBSTACLES,
    ("CellArmRequest", "obstacles"): _CELL_NO_OBSTACLES,
    ("CellRequest", "self_collision"): _CELL_SELF_COLLISION,
    ("CellArmRequest", "self_collision"): _CELL_SELF_COLLISION,
    ("CellRequest", "timing"): _CELL_TIMING,
    ("CellArmRequest", "timing"): _CELL_TIMING,
    ("JobCreate", "*"): ": put the request under `trajectory` (a POST /v1/trajectories body) or `compare` "
    "(a POST /v1/trajectories/compare body), e.g. {\"trajectory\": {\"robot\": \"ur5\", \"path\": ...}}",
}


def elsewhere(model: type[BaseModel] | None, location: str) -> str:
    """What to do with the unknown field at ``location`` when it belongs to another route
    (``ELSEWHERE``); "" otherwise."""
    if model is None:
        return ""
    if (model.__name__, location) in ELSEWHERE:
        return ELSEWHERE[model.__name__, location]
    return ELSEWHERE.get((model.__name__, "*"), "") if "." not in location and "[" not in location else ""


def unknown_field_hint(model: type[BaseModel] | None, loc: tuple[str | int, ...], location: str) -> str:
    """The hint for the unknown field at ``loc`` (``location`` as the service writes it): what
    to do with a field of another route (``elsewhere``), where a field of that name belongs
    (``hint``), else the nearest allowed name there (``nearest``), else the top of a job's
    body's advice."""
    specific = ELSEWHERE.get((model.__name__, location), "") if model is not None else ""
    if model is not None and model.__name__ == "CellRequest" and len(loc) == 3 and loc[0] == "arms":
        specific = specific or ELSEWHERE.get(("CellArmRequest", str(loc[2])), "")
    return specific or hint(model, location) or nearest(model, loc) or elsewhere(model, location)
