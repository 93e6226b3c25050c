"""Errors as ``application/problem+json`` (RFC 9457) without the web framework: the HTTP
status and title of each error class of the library (``STATUS``, ``TITLE``: ``status_of``,
``title_of``, its own class or nearest base in the table; the service's own errors carry theirs),
``detail`` that words an error in the request's vocabulary (``REQUEST_FIELD`` maps the library's
fields to the request's; ``toptraj.service.wordings`` holds one wording per rule), the problem of a
request that does not fit its schema, and the search for a NaN or infinity in an answer. The HTTP
answers (``toptraj.service.errors``), jobs, batches and the CLI all use these; ``toptraj plan`` and
the batch workers without importing FastAPI.
"""

from __future__ import annotations

import math
import string
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from pydantic import BaseModel, ValidationError

from toptraj.planners.collision.clearance import PathInCollision
from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, InvalidRequest, OverMemory, TimingFailed, WorkerStopped
from toptraj.robots import ToptrajError
from toptraj.robots.errors import (
    MAX_DETAIL_CHARS,
    CatalogRobotReadOnly,
    InvalidLimits,
    InvalidRobotName,
    InvalidUpload,
    InvalidURDF,
    RobotConflict,
    UnknownRobot,
    UploadStoreFull,
    UploadStoreUnavailable,
    excerpt,
)
from toptraj.robots.notes import Note
from toptraj.service.counts import counted
from toptraj.service.field_hints import unknown_field_hint
from toptraj.service.limit_wordings import torque_remedy
from toptraj.service.locations import where
from toptraj.service.value_hints import collapsed, value_hint
from toptraj.service.wordings import WORDING

HTTP_TITLES = {
    400: "Bad request",
    404: "Not found",
    405: "Method not allowed",
    409: "Conflict",
    413: "Request body too large",
    415: "Unsupported media type",
    422: "Invalid request",
    500: "Internal error",
    504: "Computation over its time budget",
}


#: HTTP status of the library's errors by class; a class not in the table answers with its
#: nearest base's (``ToptrajError``: 422, malformed or impossible input).
STATUS: dict[type[ToptrajError], int] = {
    ToptrajError: 422,
    UnknownRobot: 404,
    RobotConflict: 409,
    CatalogRobotReadOnly: 409,
    UploadStoreFull: 409,
    UploadStoreUnavailable: 503,
    BudgetExceeded: 504,
    WorkerStopped: 503,
}


#: Title of the library's errors by class (nearest base, as ``STATUS``).
TITLE: dict[type[ToptrajError], str] = {
    ToptrajError: "Unprocessable request",
    UnknownRobot: "Unknown robot",
    InvalidURDF: "Invalid URDF",
    RobotConflict: "Robot name taken",
    InvalidRobotName: "Invalid robot name",
    CatalogRobotReadOnly: "Catalog robot cannot be deleted",
    UploadStoreFull: "Upload store full",
    UploadStoreUnavailable: "Upload store unavailable",
    InvalidLimits: "Invalid limits",
    InvalidUpload: "Invalid upload options",
    InvalidRequest: "Invalid request",
    InfeasiblePath: "Path cannot be followed within the limits",
    PathInCollision: "Path comes too close to an obstacle",
    TimingFailed: "Timing method failed",
    WorkerStopped: "Worker stopped",
    OverMemory: "Computation over its memory cap",
    BudgetExceeded: "Computation over its time budget",
}

#: The request's field of each of the library's (``InvalidInput.field``); a library field
#: ``name[i]...`` or ``name.part`` maps by its longest listed prefix (``waypoints[2][4]`` ->
#: ``path.waypoints[2][4]``).
REQUEST_FIELD: dict[str, str] = {
    "method": "timing.method",
    "constraints": "timing.constraints",
    "grid.intervals": "timing.grid_points",
    "duration": "timing.duration",
    "boundary": "timing.boundary",
    "boundary.start_velocity": "timing.boundary.start_velocity",
    "boundary.end_velocity": "timing.boundary.end_velocity",
    "boundary.start_acceleration": "timing.boundary.start_acceleration",
    "boundary.end_acceleration": "timing.boundary.end_acceleration",
    "method.torque_weight": "timing.cost.torque_weight",
    "law.trapezoid": "timing.trapezoid",
    "law.blend": "timing.trapezoid.blend",
    "law.supporting_points": "timing.supporting_points",
    "law.synchronization": "timing.synchronization",
    "limits": "timing.limits",
    "limits.margin": "timing.limit_margin",
    "tool.frame": "timing.limits.tool_frame",
    "search": "timing.search",
    "sampling.dt": "output.dt",
    "sampling.exact_period": "output.exact_period",
    "sampling.samples": "output.dt",
    "waypoints": "path.waypoints",
    "interpolation": "path.interpolation",
    "max_deviation": "path.max_deviation",
    "continuous": "path.continuous",
    "min_spacing": "path.min_spacing",
    "start": "path.start",
    "goal": "path.goal",
    "revolutions": "path.revolutions",
    "obstacles": "path.obstacles",
    "clearance": "path.clearance",
    "frame": "path.frame",
    "positions": "path.positions",
    "poses": "path.poses",
}


def request_field(field: str) -> str:
    """The request's name of the library's ``field`` (``REQUEST_FIELD`` by its longest prefix
    ending before a ``[`` or ``.``; a field not listed is shown as it is)."""
    for end in range(len(field), 0, -1):
        if end < len(field) and field[end] not in "[.":
            continue
        head = REQUEST_FIELD.get(field[:end])
        if head is not None:
            return head + field[end:]
    return field


class _Words(string.Formatter):
    """``str.format`` with ``!j`` (join a sequence with ", "), ``!e`` (excerpt), ``!f`` (a
    library field as the request's) and ``:~noun`` (the count and the noun, plural unless one)."""

    def format_field(self, value, format_spec):
        if format_spec.startswith("~"):
            return counted(value, format_spec[1:])
        return super().format_field(value, format_spec)

    def convert_field(self, value, conversion):
        if conversion == "j":
            return ", ".join(map(str, value))
        if conversion == "e":
            return excerpt(value)
        if conversion == "f":
            return request_field(value)
        return super().convert_field(value, conversion)


_WORDS = _Words()


def detail(error: ToptrajError) -> str:
    """``error`` in the request's words: the wording of its rule (``toptraj.service.wordings``) over its
    facts, with its ``field`` as the request's; an error without a rule worded here is shown by
    its own sentence (the service's errors, and the library's that name no request field)."""
    rule = getattr(error, "rule", None)
    text = _worded(rule, dict(vars(error)), error.detail)
    held = getattr(error, "held", None)
    if held is not None:
        text += (
            f": holding still at s = {held.s:.4f} needs {held.torque:.4g} {held.unit} on joint {held.joint!r}, "
            f"above its limit of {held.limit:.4g} {held.unit}"
        )
    if rule != "not_even_at_rest":  # that rule's wording gives the remedy itself
        text += torque_remedy(vars(error))
    carried = getattr(error, "payload_carried", None)
    if carried is not None:
        higher = "" if getattr(error, "beyond_range", ()) else " or higher torque limits (timing.limits.torque)"
        text += (
            f"; the torques include the payload of {carried[0]:g} kg at {carried[1]}: a lighter payload "
            f"(payload.mass){higher} may make the path feasible"
        )
    unusual = getattr(error, "gravity_unusual", None)
    if unusual is not None:
        text += f"; {note_text(unusual)}"
    return _cut(text)


def note_text(note: str) -> str:
    """A note of an answer (``toptraj.robots.notes.Note``) in the request's words, as ``detail`` words
    an error; a plain string as it is."""
    if not isinstance(note, Note):
        return note
    return _worded(note.rule, dict(note.facts), str(note))


def _worded(rule: object, facts: dict, sentence: str) -> str:
    """The wording of ``rule`` over ``facts`` (fields mapped to the request's), or ``sentence``
    when the rule has none."""
    wording = WORDING.get(rule) if isinstance(rule, str) else None
    if wording is None:
        return sentence
    if isinstance(facts.get("field"), str):
        facts["field"] = request_field(facts["field"])
    if isinstance(facts.get("fields"), tuple):
        facts["fields"] = tuple(request_field(name) for name in facts["fields"])
    return _cut(wording(facts) if callable(wording) else _WORDS.format(wording, **facts))


def _cut(text: str) -> str:
    """``text`` within ``MAX_DETAIL_CHARS`` (a detail never echoes a large request back)."""
    if len(text) > MAX_DETAIL_CHARS:
        text = text[: MAX_DETAIL_CHARS - 20] + " ... (detail cut)"
    return text


#: The facts of an error a problem body carries beside its detail, where the error has them.
PROBLEM_FACTS = ("s", "joint", "limit", "link", "obstacle", "link_a", "link_b")


def problem_facts(error: ToptrajError) -> dict[str, Any]:
    """The facts (``PROBLEM_FACTS``) of ``error`` that a problem body carries: where along the
    path (``s``), which joint, limit, link or obstacle; those that are ``None`` left out."""
    return {key: getattr(error, key) for key in PROBLEM_FACTS if getattr(error, key, None) is not None}


def title_of(error: ToptrajError) -> str:
    """The title of ``error``'s answer: ``TITLE`` of its class or nearest base there; an error
    class of the service itself states its own."""
    for cls in type(error).__mro__:
        if cls in TITLE:
            return TITLE[cls]
        if cls.__module__.startswith("toptraj.service.") and "title" in vars(cls):
            return vars(cls)["title"]
    return TITLE[ToptrajError]


def status_of(error: ToptrajError) -> int:
    """The HTTP status of ``error``: ``STATUS`` of its class or nearest base there; an error
    class of the service itself (``service.*``: a busy queue, an unknown job) states its own."""
    for cls in type(error).__mro__:
        if cls in STATUS:
            return STATUS[cls]
        if cls.__module__.startswith("toptraj.service.") and "status" in vars(cls):
            return vars(cls)["status"]
    return STATUS[ToptrajError]


class RequestRefused(ToptrajError):
    """A request the service refuses by its own rules (a job's kind, a cursor, a budget above the
    server's cap, a skeleton's configurations), in the service's words."""

    title = "Invalid request"


#: What pydantic puts before the sentence of a ``ValueError`` raised by a schema's validator.
_VALUE_ERROR_PREFIX = "Value error, "


def validation_message(item: Mapping[str, Any]) -> str:
    """pydantic's message of one error ``item`` (an entry of ``errors()``) as the service's own
    sentence: a schema validator's sentence without pydantic's "Value error, " before it, a list's
    count without "after validation" (the request's count is meant), and the
    value given where the choice was among names (an enum), short values only, so that no error
    echoes a large input."""
    message = item["msg"]
    if item.get("type") == "value_error" and message.startswith(_VALUE_ERROR_PREFIX):
        message = message[len(_VALUE_ERROR_PREFIX) :]
    if item.get("type") in ("too_short", "too_long"):  # a list's count as the request gives it
        message = message.replace(" after validation", "")
    value = item.get("input")
    if item.get("type") == "literal_error" and isinstance(value, str) and len(value) <= 60:
        message += f", not {value!r}"
    return message


#: Errors of a malformed request named in a problem's detail, and listed in its ``errors``.
_DETAIL_ERRORS, LISTED_ERRORS = 5, 20


def validation_errors(items: Iterable[Mapping[str, Any]], model: object = None) -> tuple[list[dict[str, str]], int]:
    """The first ``LISTED_ERRORS`` errors of a request that does not fit its schema ``model``
    (``errors()`` items, their locations relative to the body, or under ``"body"``) as
    ``{"field", "message"}``, and how many there are in all (the others only counted): the place
    as the service writes places (``timing.zones[0]``), the message in the service's words, and
    for a field the schema does not know, where it belongs or the name it was likely meant as."""
    schema = model if isinstance(model, type) and issubclass(model, BaseModel) else None
    collapsed_items = collapsed(list(items))
    cell = [item for item in collapsed_items if item.get("type") == "extra_forbidden" and _relative(item["loc"]) == ("arms",)]
    if cell:  # a cell's body sent to another route: where it goes is the one thing to say
        collapsed_items = cell
    errors = []
    for item in collapsed_items[:LISTED_ERRORS]:
        loc = tuple(item["loc"])
        field = where(loc)
        message = validation_message(item) + value_hint(item)
        if item.get("type") == "extra_forbidden":
            message += unknown_field_hint(schema, loc[1:] if loc[:1] == ("body",) else loc, field)
        errors.append({"field": field, "message": message})
    return errors, len(collapsed_items)


def _relative(loc) -> tuple:
    """An error's location relative to the body."""
    loc = tuple(loc)
    return loc[1:] if loc[:1] == ("body",) else loc


def validation_detail(errors: list[dict[str, str]], count: int | None = None) -> str:
    """The detail of a 422 with ``errors`` (``validation_errors``), ``count`` in all (default:
    as many as listed): the first few, then how many more."""
    count = len(errors) if count is None else count
    detail = "; ".join(f"{item['field']}: {item['message']}" for item in errors[:_DETAIL_ERRORS])
    if count > _DETAIL_ERRORS:
        detail += f"; and {count - _DETAIL_ERRORS} more"
    return detail


def validation_problem(error: ValidationError, model: object = None) -> dict:
    """The problem+json of a request that does not fit its schema ``model`` (as the HTTP API's 422)."""
    errors, count = validation_errors(error.errors(include_url=False), model)
    return {"type": "about:blank", "title": "Invalid request", "status": 422, "detail": validation_detail(errors, count), "errors": errors}


class NonFiniteAnswer(ToptrajError):
    """A computed answer holds NaN or infinity, which JSON cannot carry: the request's numbers
    drove a computation out of the floating-point range."""

    title = "Answer not representable"


def non_finite_answer(content: Any) -> NonFiniteAnswer | None:
    """The ``NonFiniteAnswer`` naming the first NaN or infinity in ``content`` (dicts, lists
    and numpy arrays), or ``None`` when every number is finite."""
    where, value = _first_non_finite(content, "")
    if where is None:
        return None
    return NonFiniteAnswer(
        f"the computed answer holds {value} at {where or 'its top level'}, which JSON cannot "
        "carry; the request's numbers lie too far apart (durations, limits, boundary states)"
    )


def _first_non_finite(value: Any, where: str) -> tuple[str | None, float | None]:
    """(place, value) of the first NaN or infinity in ``value`` at ``where``, or (None, None).
    Strings, integers and ``None`` inside a container are passed over and floats tested in
    place, without a call each; arrays in one numpy pass."""
    if isinstance(value, float):
        return (None, None) if math.isfinite(value) else (where, value)
    if isinstance(value, np.ndarray):
        if value.dtype.kind != "f" or np.isfinite(value).all():
            return None, None
        bad = np.argwhere(~np.isfinite(value))[0]
        return where + "".join(f"[{i}]" for i in bad), float(value[tuple(bad)])
    if isinstance(value, dict):
        items: Iterable[tuple[Any, Any]] = value.items()
        dotted = True
    elif isinstance(value, (list, tuple)):
        if _all_finite_numbers(value):
            return None, None
        items, dotted = enumerate(value), False
    else:
        return None, None
    for key, item in items:
        if item is None or isinstance(item, (str, int)):
            continue
        if isinstance(item, float) and math.isfinite(item):
            continue
        place = (f"{where}.{key}" if where else str(key)) if dotted else f"{where}[{key}]"
        found = _first_non_finite(item, place)
        if found[0] is not None:
            return found
    return None, None


def _all_finite_numbers(values: list | tuple) -> bool:
    """Whether ``values`` is a flat sequence of finite numbers, checked in one numpy pass (a
    sequence holding anything else is walked item by item instead)."""
    if not values or not isinstance(values[0], (int, float)):
        return False
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        return False
    return array.ndim == 1 and bool(np.isfinite(array).all())


