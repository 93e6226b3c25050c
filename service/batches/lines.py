"""Request lines and result lines of a batch (JSON Lines).

A request line is the body of ``POST /v1/trajectories`` or, when it names ``methods``, of
``POST /v1/trajectories/compare``. Its key is the SHA-256 of its canonical JSON (keys sorted,
no spaces), or of the line's text when it is no JSON: the same request gets the same key
whatever its formatting. A result line is ``{"key", "line", "status", "body"}``: the 1-based
line number, the HTTP status the service would answer and its body (the answer, or the
problem+json).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class RequestLine:
    """One request: its 1-based ``number``, its ``text`` and its ``key``."""

    number: int
    text: str
    key: str


def request_key(text: str) -> str:
    """The key of a request line: SHA-256 of its canonical JSON, or of its text."""
    try:
        canonical = json.dumps(json.loads(text), sort_keys=True, separators=(",", ":"))
    except ValueError:
        canonical = text
    return hashlib.sha256(canonical.encode()).hexdigest()


def read_requests(path: Path) -> list[RequestLine]:
    """The non-blank lines of ``path`` as requests."""
    requests = []
    with open(path, encoding="utf-8") as handle:
        for number, text in enumerate(handle, start=1):
            text = text.strip()
            if text:
                requests.append(RequestLine(number, text, request_key(text)))
    return requests


def done_keys(path: Path) -> set[str]:
    """Keys of the results already in ``path`` (none if it does not exist). A line that does
    not parse (the last one of an interrupted run) is ignored, and the file is cut back to the
    lines that do, so that appending continues cleanly."""
    if not path.exists():
        return set()
    keys, keep = set(), 0
    with open(path, "rb") as handle:
        for raw in handle:
            if not raw.endswith(b"\n"):
                break
            try:
                keys.add(json.loads(raw)["key"])
            except (ValueError, KeyError, TypeError):
                break
            keep += len(raw)
    with open(path, "r+b") as handle:
        handle.truncate(keep)
    return keys
