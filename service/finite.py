"""Answers that JSON can carry: ``FiniteJSONResponse`` refuses NaN and infinity (JSON has no
such numbers) with a ``NonFiniteAnswer`` (422) that says where the answer held one, instead of
an encoder crash or invalid JSON."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from typing import Any

import numpy as np
from fastapi.responses import JSONResponse

from toptraj.robots import ToptrajError


class NonFiniteAnswer(ToptrajError):
    """A computed answer holds NaN or infinity, which JSON cannot carry: the request's numbers
    drove a computation out of the floating-point range."""

    title = "Answer not representable"


class FiniteJSONResponse(JSONResponse):
    """JSON that never carries NaN or infinity: such a number is a ``NonFiniteAnswer`` (422)
    naming where it is, never invalid JSON and never an encoder crash."""

    def render(self, content: Any) -> bytes:
        try:
            return json.dumps(content, ensure_ascii=False, allow_nan=False, separators=(",", ":")).encode("utf-8")
        except ValueError:
            error = non_finite_answer(content)
            if error is None:
                raise
            raise error from None


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
