"""Errors as ``application/problem+json`` (RFC 9457) without the web framework: the HTTP status
of each error class of the library, the problem of a request that does not fit its schema and the
search for a NaN or infinity in an answer. ``toptraj plan`` and the batch workers answer with
these, without importing FastAPI; ``toptraj.service.errors`` serves them over HTTP.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np
from pydantic import ValidationError

from toptraj.planners.errors import BudgetExceeded
from toptraj.robots import ToptrajError
from toptraj.robots.errors import CatalogRobotReadOnly, RobotConflict, UnknownRobot, UploadStoreFull, UploadStoreUnavailable

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
}


def status_of(error: ToptrajError) -> int:
    """The HTTP status of ``error``: ``STATUS`` of its class or nearest base there; an error
    class of the service itself (``toptraj.service.*``: a busy queue, an unknown job) states its own."""
    for cls in type(error).__mro__:
        if cls in STATUS:
            return STATUS[cls]
        if cls.__module__.startswith("toptraj.service.") and "status" in vars(cls):
            return vars(cls)["status"]
    return STATUS[ToptrajError]


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


def validation_problem(error: ValidationError) -> dict:
    """The problem+json of a request that does not fit its schema (as the HTTP API's 422)."""
    detail = "; ".join(f"{'.'.join(map(str, e['loc'])) or 'body'}: {e['msg']}" for e in error.errors())
    return {"type": "about:blank", "title": "Invalid request", "status": 422, "detail": detail}
