"""Request lines and result lines of a batch (JSON Lines).

A request line is the body of ``POST /v1/trajectories`` or, when it names ``methods``, of
``POST /v1/trajectories/compare``. Every line of the file, whatever it holds, gets exactly one
result line carrying its 1-based line number::

    {"line": 7, "key": "<sha-256 hex>", "status": 200, "body": {...}}

``status`` is the HTTP status the service would answer and ``body`` its body (the answer, or
the problem+json). ``key`` is the SHA-256 of the request's canonical JSON (keys sorted, no
spaces), or of the line's bytes when it is no JSON object: identical requests share a key (and
one computation) whatever their formatting, but each line has its own result line. Result
lines are written in the order they finish; sort by ``line`` for the file's order.

A line is read without trusting it: at most ``MAX_LINE_BYTES`` bytes are kept (the rest of a
longer line is skipped unread), its nesting depth is counted by a scan that cannot recurse
before any parser sees it, and a line that is empty, too long, too deep, not UTF-8, not JSON,
not a JSON object or an object giving a key twice (``toptraj.service.strict_json``) becomes its
own 4xx result line (``RequestLine.problem``).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import orjson

from toptraj.robots.errors import excerpt
from toptraj.service.strict_json import (
    DuplicateKey,
    NumberOutOfRange,
    NumberTooLong,
    decode_error,
    loads,
    refused_depth,
    too_deep,
)

#: Longest request line read, in bytes (the HTTP API's default body cap).
MAX_LINE_BYTES = 2_000_000
#: Characters of a parser's message kept in a problem's detail.
_MAX_DETAIL = 200


@dataclass(frozen=True)
class RequestLine:
    """Line ``number`` (1-based) of a request file: its request ``text`` and ``key``, or the
    ``problem`` (status, problem+json bytes) that is its result when it cannot be read."""

    number: int
    key: str
    text: str = ""
    problem: tuple[int, bytes] | None = None


def problem_body(status: int, title: str, detail: str) -> bytes:
    """A problem+json body (``detail`` cut to a bounded length)."""
    if len(detail) > 4 * _MAX_DETAIL:
        detail = detail[: 4 * _MAX_DETAIL] + "..."
    return orjson.dumps({"type": "about:blank", "title": title, "status": status, "detail": detail})


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def parse_line(number: int, raw: bytes) -> RequestLine:
    """Line ``number`` of a file as a request, or as the 4xx problem that is its result."""
    data = raw.strip(b" \t\r\n")

    def refused(status: int, title: str, detail: str) -> RequestLine:
        return RequestLine(number, _digest(data), problem=(status, problem_body(status, title, f"line {number}: {detail}")))

    if not data:
        return refused(422, "Invalid request", "the line is blank; put one request (a JSON object) on each line, or remove the line")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        return refused(422, "Invalid request", f"the line is not UTF-8 text ({error.reason} at byte {error.start}); write the file in UTF-8")
    depth = refused_depth(data)
    if depth is not None:
        return refused(400, "Too deeply nested", f"the line {too_deep(depth)}")
    try:
        body = loads(text, finite=True)
    except DuplicateKey as error:
        return refused(422, "Invalid request", str(error))
    except json.JSONDecodeError as error:
        # a line is one line of JSON text: its column is the place
        return refused(422, "Invalid request", decode_error(error).replace("line 1, column", "column", 1)[:_MAX_DETAIL])
    except (NumberTooLong, NumberOutOfRange) as error:
        return refused(422, "Invalid request", str(error))
    except ValueError as error:  # NaN or Infinity
        return refused(422, "Invalid request", f"the line is not JSON: {str(error)[:_MAX_DETAIL]}")
    if not isinstance(body, dict):
        return refused(
            422, "Invalid request", f"the line is a JSON {_JSON_TYPES.get(type(body), 'value')}; a request is a JSON object (a POST /v1/trajectories body)"
        )
    try:
        canonical = orjson.dumps(body, option=orjson.OPT_SORT_KEYS)
    except orjson.JSONEncodeError as error:  # what JSON text allows but no JSON reader agrees on
        return refused(
            422, "Invalid request",
            f"the line holds a value JSON readers do not agree on ({str(error)[:_MAX_DETAIL]}): write strings as valid "
            "Unicode (no lone \\ud800-\\udfff escape) and integers within 64 bits",
        )
    return RequestLine(number, _digest(canonical), text=text)


#: JSON's names of the values a line may hold instead of an object.
_JSON_TYPES = {list: "array", str: "string", int: "number", float: "number", bool: "boolean", type(None): "null"}


def request_key(text: str | bytes) -> str:
    """The key of a request line (``RequestLine.key``)."""
    return parse_line(1, text.encode() if isinstance(text, str) else text).key


def read_requests(path: Path, skip: set[int] | frozenset[int] = frozenset()) -> Iterator[RequestLine]:
    """Every line of ``path`` but the numbers in ``skip``, as requests (``parse_line``); a line
    longer than ``MAX_LINE_BYTES`` is a 413 problem, its bytes beyond the cap skipped unread."""
    with open(path, "rb") as handle:
        number = 0
        while raw := handle.readline(MAX_LINE_BYTES + 1):
            number += 1
            if len(raw) > MAX_LINE_BYTES and not raw.endswith(b"\n"):
                size, digest = len(raw), hashlib.sha256(raw)  # the line's bytes hashed as they are skipped
                while not raw.endswith(b"\n") and (raw := handle.readline(1 << 20)):
                    size += len(raw)
                    digest.update(raw)
                size -= raw.endswith(b"\n")
                if number not in skip:
                    detail = f"line {number}: the line has {size} bytes; a request line has at most {MAX_LINE_BYTES}"
                    yield RequestLine(number, digest.hexdigest(), problem=(413, problem_body(413, "Line too long", detail)))
                continue
            if number == 1:
                raw = raw.removeprefix(b"\xef\xbb\xbf")  # a byte order mark some editors write
            if number not in skip:
                yield parse_line(number, raw)


def result_line(number: int, key: str, status: int, body: bytes) -> bytes:
    """A result line ``{"line", "key", "status", "body"}`` with its newline, the body (JSON
    bytes) spliced in as it is."""
    head = orjson.dumps({"line": number, "key": key, "status": status})[:-1]
    return head + b',"body":' + body + b"}\n"


def retryable(status: int) -> bool:
    """A result worth computing again (``--retry-failed``): a budget error (504) or a 5xx."""
    return status >= 500


class ForeignOutput(ValueError):
    """The output file of a batch holds lines that are no result lines (another file given
    as ``--output``, the request file itself): it is left as it is."""


def resume_output(path: Path, retry_failed: bool = False, requests_path: Path | None = None) -> dict[int, int]:
    """The status of each line number already answered in ``path`` (none if it does not
    exist), with ``path`` made ready for appending: its last line cut when it has no newline
    (the last one of an interrupted run), a line number's second result dropped, with
    ``retry_failed`` the retryable results dropped, and with ``requests_path`` the results of
    lines whose request changed since (their key is no longer the line's: a request fixed after
    its 4xx is planned again), unless they are more than half (``ForeignOutput``: the output of
    another request file, whose results would all be dropped). What is dropped is written to a new file that replaces the old
    one, so an interruption leaves one or the other.

    Raises:
        ForeignOutput: a whole line of ``path`` is no result line, or most of its results are of
            other requests; nothing is changed.
    """
    if not path.exists():
        return {}
    done: dict[int, int] = {}
    keys: dict[int, str] = {}
    kept: dict[int, tuple[int, int]] = {}  # line number -> (offset, length) of its result kept
    offset, dropped = 0, False
    with open(path, "rb") as handle:
        for count, raw in enumerate(handle, start=1):
            if not raw.endswith(b"\n"):
                break  # cut short by an interruption: written again
            try:
                row = orjson.loads(raw)
                number, status, key = int(row["line"]), int(row["status"]), row.get("key")
                if not isinstance(key, str) or "body" not in row:
                    raise KeyError("key")
            except (ValueError, KeyError, TypeError, AttributeError):
                raise ForeignOutput(
                    f"{excerpt(str(path))}: line {count} is no result line of toptraj batch, so the file is no output of "
                    "one and is left as it is; give another --output (a new file, or the output of an earlier run to "
                    "resume it)"
                ) from None
            if number in done or (retry_failed and retryable(status)):
                dropped = True
            else:
                done[number], keys[number] = status, key
                kept[number] = (offset, len(raw))
            offset += len(raw)
    if requests_path is not None and done and requests_path.exists():
        changed = _changed(path, requests_path, keys)
        for number in changed:
            del done[number], kept[number]
        dropped = dropped or bool(changed)
    keep = sorted(kept.values())
    if not dropped:
        with open(path, "r+b") as handle:
            handle.truncate(offset)
        return done
    fresh = path.with_name(path.name + ".resuming")
    with open(path, "rb") as source, open(fresh, "wb") as target:
        for start, length in keep:
            source.seek(start)
            target.write(source.read(length))
        target.flush()
        os.fsync(target.fileno())
    os.replace(fresh, path)
    return done


def _changed(path: Path, requests_path: Path, keys: dict[int, str]) -> list[int]:
    """The line numbers of ``requests_path`` whose request is no longer the one the result in
    ``path`` answered (``keys``: each result's key by line number).

    Raises:
        ForeignOutput: more than half of them (and more than one): ``path`` is the output of
            another request file.
    """
    changed = [line.number for line in read_requests(requests_path) if line.number in keys and keys[line.number] != line.key]
    if len(changed) > 1 and 2 * len(changed) > len(keys):
        raise ForeignOutput(
            f"{excerpt(str(path))}: {len(changed)} of its {len(keys)} results are of other requests than the lines of "
            f"{excerpt(str(requests_path))} hold now, so it is the output of another request file and is left as it "
            "is; give another --output, or the request file that made it (lines changed since, fewer than half, are "
            "planned again)"
        )
    return changed
