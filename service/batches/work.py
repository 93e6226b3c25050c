"""One request answered as the service answers it, on whichever process runs it (a Ray
worker): the same schemas and the same path through ``service.planning``, so a batch's result
equals the synchronous endpoint's answer."""

from __future__ import annotations

import json
import tempfile

import orjson
from pydantic import ValidationError

import robots
from planners.deadline import Deadline
from robots import ToptrajError
from robots.upload_options import UploadOptions
from service.commands import validation_problem
from service.planning import compare_request, encode_json, plan_request, render
from service.schemas.trajectories import CompareRequest, TrajectoryRequest

_configured = False


def _uploads_here(uploads: dict[str, tuple[str, str]]) -> None:
    """Make the uploaded robots a batch uses available in this process: a worker on another
    machine has no access to the server's data directory, so their URDF texts and options
    (``UploadOptions.to_json``) travel with the tasks and are registered in a store of the
    worker's own."""
    global _configured
    if not uploads:
        return
    if not _configured:
        robots.configure_uploads(tempfile.mkdtemp(prefix="toptraj-batch-uploads-"))
        _configured = True
    for name, (urdf, options) in uploads.items():
        robots.register_urdf(urdf, name, UploadOptions.from_json(options))


def _problem_bytes(status: int, title: str, detail: str, **extra) -> bytes:
    return orjson.dumps({"type": "about:blank", "title": title, "status": status, "detail": detail, **extra})


def answer(text: str, budget_s: float) -> tuple[int, bytes]:
    """(status, body as JSON bytes) of one request line: 200 and the answer, or the problem's
    status and problem+json. ``budget_s`` bounds the computation as the synchronous budget
    does. The answer stays the bytes the endpoint would send (never decoded and re-encoded)."""
    try:
        body = json.loads(text)
    except ValueError as error:
        return 400, _problem_bytes(400, "Malformed JSON", f"the line is not JSON: {error}")
    try:
        if isinstance(body, dict) and "methods" in body:
            return 200, encode_json(compare_request(CompareRequest.model_validate_json(text), Deadline(budget_s)))
        request = TrajectoryRequest.model_validate_json(text)
        content, media_type = render(plan_request(request, Deadline(budget_s)), request)
        return 200, content if media_type == "application/json" else orjson.dumps(content.decode())
    except ValidationError as error:
        return 422, orjson.dumps(validation_problem(error))
    except ToptrajError as error:
        extra = {key: getattr(error, key) for key in ("s", "joint", "limit", "link", "obstacle") if hasattr(error, key)}
        return error.status, _problem_bytes(error.status, error.title, error.detail, **extra)


def result_line(key: str, number: int, status: int, body: bytes) -> bytes:
    """A result line ``{"key", "line", "status", "body"}`` with its newline, the body spliced in
    as it is."""
    head = orjson.dumps({"key": key, "line": number, "status": status})[:-1]
    return head + b',"body":' + body + b"}\n"


def answer_chunk(chunk: list[tuple[str, str, int]], uploads: dict[str, tuple[str, str]], budget_s: float) -> list[bytes]:
    """Result lines (bytes) of a chunk of (key, text, line number) requests."""
    _uploads_here(uploads)
    return [result_line(key, number, *answer(text, budget_s)) for key, text, number in chunk]
