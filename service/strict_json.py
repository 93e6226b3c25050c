"""JSON text read strictly: a key given twice in one object is refused (``DuplicateKey``, naming
the key and its place) instead of the last one silently winning, as Python's ``json`` and
orjson both let it. Every request body the service reads goes through ``loads``: the HTTP
bodies (``toptraj.service.strict_routes``), the lines of a batch and the CLI's files.

The text is parsed once, by ``json``'s C scanner, with a hook on each object; the place of a
duplicate is looked for only when there is one, by a walk without recursion."""

from __future__ import annotations

import json
import math
import re
import sys
from collections import Counter
from typing import Any

import numpy as np

from toptraj.robots.errors import excerpt
from toptraj.service.locations import joined

#: Characters of a key shown in a place.
MAX_KEY_CHARS = 60
#: Deepest nesting of arrays and objects in a request (a request needs 5, a batch's body 7).
MAX_DEPTH = 32
#: A JSON string (its brackets are no nesting): a quote, runs of other bytes each ended by an
#: escape, a quote; unrolled (Friedl's "unrolling the loop") so that a string never closed
#: costs linear time, where alternatives under a star backtrack exponentially.
_STRING = re.compile(rb'"[^"\\]*(?:\\.[^"\\]*)*"', re.DOTALL)
_OPEN = np.frombuffer(b"[{", dtype=np.uint8)
_CLOSE = np.frombuffer(b"]}", dtype=np.uint8)


#: The answer to an empty request body or file.
EMPTY_BODY = 'the body is empty; send a JSON object (e.g. {"robot": "ur5", "path": ...})'


def nesting_depth(data: bytes) -> int:
    """The deepest nesting of ``[`` and ``{`` in ``data`` (outside JSON strings), counted
    without recursion: strings removed by one regular expression, then a running sum of +1 per
    opening and -1 per closing bracket. An unterminated string counts its brackets."""
    codes = np.frombuffer(_STRING.sub(b"", data), dtype=np.uint8)
    steps = np.isin(codes, _OPEN).astype(np.int64) - np.isin(codes, _CLOSE)
    return int(np.cumsum(steps).max(initial=0))


def refused_depth(data: bytes) -> int | None:
    """How deep ``data`` (UTF-8: in UTF-16 or UTF-32 a quote byte can be part of another
    character) nests when that is deeper than a request may (``MAX_DEPTH``), else ``None``:
    checked before the text is parsed, so that nothing is built from a text too deep. A text
    with at most ``MAX_DEPTH`` opening brackets cannot nest deeper, which two counts decide
    for the usual request (a microsecond, against some 40 for ``nesting_depth``)."""
    if data.count(b"[") + data.count(b"{") <= MAX_DEPTH:
        return None
    depth = nesting_depth(data)
    return depth if depth > MAX_DEPTH else None


def too_deep(depth: int) -> str:
    """What is wrong with a text nesting ``depth`` levels, more than a request may
    (``MAX_DEPTH``), as the end of a sentence about it ("the body ...")."""
    return f"is nested too deeply: it nests arrays and objects {depth} deep; a request nests at most {MAX_DEPTH} levels"


def decode_error(error: json.JSONDecodeError) -> str:
    """Where and why ``json`` could not read a text, in words a person can act on: the line
    and column, the parser's own message and, for the usual slips (single quotes, a trailing
    comma, a text cut short), what to change (``line 3, column 5: Expecting ',' delimiter``)."""
    text = error.doc if isinstance(error.doc, str) else ""
    found = text[error.pos : error.pos + 1]
    before = text[: error.pos].rstrip()
    if not text.strip():
        return EMPTY_BODY
    message = f"line {error.lineno}, column {error.colno}: {error.msg}"
    if found == "'":
        return message + " (JSON needs double quotes: write \"robot\", not 'robot')"
    if found in "}]" and found and before.endswith(","):
        return message + f" (a comma before {found!r}: JSON allows no trailing comma; remove it)"
    if error.pos >= len(text.rstrip()):
        return message + " (the text ends before the JSON does: is it cut short, a bracket or brace left open?)"
    return message


class NumberTooLong(ValueError):
    """A JSON text holds an integer of more digits than Python converts (``sys.get_int_max_str_digits``)."""

    def __init__(self) -> None:
        super().__init__(
            f"a number has more than {sys.get_int_max_str_digits()} digits; a request's numbers (joint values, limits, "
            "settings) need a few"
        )


class NumberOutOfRange(ValueError):
    """A JSON text holds a number beyond a double's range (``1e400``), which would be read as an
    infinity."""

    def __init__(self, text: str) -> None:
        shown = text if len(text) <= 24 else f"{text[:24]}..."
        super().__init__(f"the number {shown} is beyond the range of a double (about ±1.8e308); give a finite number")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise NumberOutOfRange(text)
    return value


class DuplicateKey(ValueError):
    """An object of a JSON text gives ``key`` ``count`` times; ``where`` is the key's place
    (``timing.zones[0].tool_speed``)."""

    def __init__(self, key: str, where: str, count: int):
        self.key, self.where, self.count = key, where, count
        self.message = (
            f"the key {excerpt(key)} is given {count} times in one object; a JSON parser would silently keep the last: "
            "give each field once"
        )
        super().__init__(f"{where}: {self.message}")

    def problem(self) -> dict:
        """The 422 problem+json of the refusal, its ``errors`` as a schema's refusals list theirs."""
        return {
            "type": "about:blank",
            "title": "Invalid request",
            "status": 422,
            "detail": str(self),
            "errors": [{"field": self.where, "message": self.message}],
        }


def _refuse_constant(name: str) -> float:
    raise ValueError(f"{name} is no JSON number")


def loads(data: str | bytes, finite: bool = False) -> Any:
    """The value of the JSON text ``data``, every key of each object given once; with
    ``finite``, ``NaN`` and ``Infinity`` are refused as no JSON.

    Raises:
        json.JSONDecodeError: ``data`` is no JSON (a ``ValueError``).
        ValueError: with ``finite``, ``data`` holds ``NaN``, ``Infinity`` or ``-Infinity``.
        NumberTooLong: an integer of more digits than Python converts.
        NumberOutOfRange: with ``finite``, a number beyond a double's range (``1e400``).
        DuplicateKey: an object gives a key more than once (the first such object to end that
            the parsed value still holds: an object a later repeated key replaced has no place).
        RecursionError: ``data`` nests deeper than the interpreter's recursion limit.
    """
    duplicated: list[tuple[dict, str, int]] = []

    def pairs(items: list[tuple[str, Any]]) -> dict:
        value = dict(items)
        if len(value) != len(items):
            key, count = Counter(key for key, _ in items).most_common(1)[0]
            duplicated.append((value, key, count))
        return value

    try:
        value = json.loads(
            data, object_pairs_hook=pairs, parse_constant=_refuse_constant if finite else None, parse_float=_finite_float if finite else None
        )
    except (json.JSONDecodeError, NumberOutOfRange):
        raise
    except ValueError as error:
        if "digits" in str(error) and "integer" in str(error):  # int("9" * 5000): Python's conversion limit
            raise NumberTooLong() from None
        raise
    if duplicated:
        places = _places_of(value, {id(holder) for holder, _, _ in duplicated})
        holder, key, count = next(item for item in duplicated if id(item[0]) in places)
        raise DuplicateKey(key, joined(_short(part) for part in [*places[id(holder)], key]), count)
    return value


def _short(part: str | int) -> str | int:
    """A key as a place shows it: its first ``MAX_KEY_CHARS`` characters."""
    return part[:MAX_KEY_CHARS] + "..." if isinstance(part, str) and len(part) > MAX_KEY_CHARS else part


def _places_of(root: Any, targets: set[int]) -> dict[int, list[str | int]]:
    """{id of an object of ``targets`` that ``root`` holds: the keys and indices that lead to it}."""
    found: dict[int, list[str | int]] = {}
    stack: list[tuple[Any, list[str | int]]] = [(root, [])]
    while stack:
        value, place = stack.pop()
        if id(value) in targets:
            found[id(value)] = place
        if isinstance(value, dict):
            stack.extend((item, [*place, key]) for key, item in value.items() if isinstance(item, dict | list))
        elif isinstance(value, list):
            stack.extend((item, [*place, index]) for index, item in enumerate(value) if isinstance(item, dict | list))
    return found
