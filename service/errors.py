"""Errors as ``application/problem+json`` (RFC 9457): the status, title and words of each
error, one handler per family and an outermost guard for the unexpected.

* ``STATUS`` and ``TITLE`` give the HTTP status and title of each error class of the library
  (``status_of``, ``title_of``: its own class or nearest base in the table; the service's own
  errors carry theirs); ``detail`` words an error in the request's vocabulary
  (``REQUEST_FIELD`` maps the library's fields to the request's; ``toptraj.service.wordings`` holds one
  wording per rule). The HTTP answers, jobs, batches and the CLI all use these.
* ``install_problem_handlers`` routes the error tree (``ToptrajError``), request validation and
  Starlette's HTTP errors (404, 405 with its ``Allow`` header, ...) to problem answers.
* ``UnexpectedErrors`` (pure ASGI, outermost) answers any other exception with a problem 500
  and lets the server keep the connection: Starlette's own last-resort handler re-raises after
  answering, and uvicorn then drops the keep-alive connection without ``Connection: close``,
  so a client's next request on it fails.
* ``toptraj.service.finite.FiniteJSONResponse`` refuses NaN and infinity (JSON has no such numbers)
  with a 422 that says where the answer held one, instead of an encoder crash.
* ``toptraj.service.problem_docs`` makes the OpenAPI declare these answers.
"""

from __future__ import annotations

import logging
import string

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import ValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.routing import Match

from toptraj.planners.collision.clearance import PathInCollision
from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, InvalidRequest, OverMemory, TimingFailed
from toptraj.robots import ToptrajError
from toptraj.robots.errors import (
    MAX_DETAIL_CHARS,
    CatalogRobotReadOnly,
    InvalidLimits,
    InvalidRobotName,
    InvalidURDF,
    RobotConflict,
    UnknownRobot,
    UploadStoreFull,
    UploadStoreUnavailable,
    excerpt,
)
from toptraj.robots.notes import Note
from toptraj.robots.upload_options import InvalidUpload
from toptraj.service.problem_docs import PROBLEM_JSON, declare_problems
from toptraj.service.wordings import WORDING

logger = logging.getLogger("toptraj")

_TITLES = {
    400: "Bad request",
    404: "Not found",
    405: "Method not allowed",
    409: "Conflict",
    413: "Request body too large",
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
    """``str.format`` with ``!j`` (join a sequence with ", "), ``!e`` (excerpt) and ``!f`` (a
    library field as the request's)."""

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
            f": holding still at s = {held.s:.4f} needs {held.torque:.4g} N m on joint {held.joint!r}, "
            f"above its limit of {held.limit:.4g} N m"
        )
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


def title_of(error: ToptrajError) -> str:
    """The title of ``error``'s answer: ``TITLE`` of its class or nearest base there; an error
    class of the service itself states its own."""
    for cls in type(error).__mro__:
        if cls in TITLE:
            return TITLE[cls]
        if cls.__module__.partition(".")[0] == "service" and "title" in vars(cls):
            return vars(cls)["title"]
    return TITLE[ToptrajError]


def status_of(error: ToptrajError) -> int:
    """The HTTP status of ``error``: ``STATUS`` of its class or nearest base there; an error
    class of the service itself (``service.*``: a busy queue, an unknown job) states its own."""
    for cls in type(error).__mro__:
        if cls in STATUS:
            return STATUS[cls]
        if cls.__module__.partition(".")[0] == "service" and "status" in vars(cls):
            return vars(cls)["status"]
    return STATUS[ToptrajError]


class RequestRefused(ToptrajError):
    """A request the service refuses by its own rules (a job's kind, a cursor, a budget above the
    server's cap, a skeleton's configurations), in the service's words."""

    title = "Invalid request"


def validation_problem(error: ValidationError) -> dict:
    """The problem+json of a request that does not fit its schema (as the HTTP API's 422)."""
    detail = "; ".join(f"{'.'.join(map(str, e['loc'])) or 'body'}: {e['msg']}" for e in error.errors())
    return {"type": "about:blank", "title": "Invalid request", "status": 422, "detail": detail}


def problem(status: int, title: str, detail: str, headers: dict[str, str] | None = None, **extra) -> JSONResponse:
    """A problem+json response."""
    body = {"type": "about:blank", "title": title, "status": status, "detail": detail}
    body.update({key: value for key, value in extra.items() if value is not None})
    return JSONResponse(body, status_code=status, media_type=PROBLEM_JSON, headers=headers)


#: Tags of the path union that pydantic puts in error locations: path.<tag>.<field>.
_PATH_TAGS = ("waypoints", "cartesian", "free")


def _location(loc) -> str:
    parts = [str(part) for part in loc if part not in ("body",)]
    for index in range(len(parts) - 2):  # path.<tag>.<field>, at the top or in a job
        if parts[index] == "path" and parts[index + 1] in _PATH_TAGS:
            del parts[index + 1]
            break
    text = ""
    for part in parts:
        text += f"[{part}]" if part.isdigit() else (f".{part}" if text else part)
    return text or "body"


def _toptraj_error(request: Request, error: ToptrajError) -> JSONResponse:
    extra = {key: getattr(error, key) for key in ("s", "joint", "limit", "link", "obstacle") if hasattr(error, key)}
    retry_after = getattr(error, "retry_after", None)
    headers = None if retry_after is None else {"Retry-After": str(retry_after)}
    return problem(status_of(error), title_of(error), detail(error), headers, **extra)


def _message(item: dict) -> str:
    """pydantic's message, with the value given where the choice was among names (an enum):
    short values only, so that no error echoes a large input."""
    message = item["msg"]
    value = item.get("input")
    if item.get("type") == "literal_error" and isinstance(value, str) and len(value) <= 60:
        message += f", not {value!r}"
    return message


def _validation_error(request: Request, error: RequestValidationError) -> JSONResponse:
    errors = [
        {"field": _location(item["loc"]), "message": _message(item)} for item in error.errors()
    ]
    detail = "; ".join(f"{item['field']}: {item['message']}" for item in errors[:5])
    if len(errors) > 5:
        detail += f"; and {len(errors) - 5} more"
    return problem(422, "Invalid request", detail, errors=errors[:20])


def _http_error(request: Request, error: StarletteHTTPException) -> JSONResponse:
    headers = None if error.headers is None else dict(error.headers)
    if error.status_code == 405:
        allowed = _allowed_methods(request)
        headers = {**(headers or {}), "Allow": ", ".join(allowed)}
        detail = f"{request.method} is not allowed on {request.url.path}; use {' or '.join(allowed)}"
    else:
        detail = str(error.detail)
    return problem(error.status_code, _TITLES.get(error.status_code, "HTTP error"), detail, headers=headers)


_METHODS = ("DELETE", "GET", "HEAD", "PATCH", "POST", "PUT")


def _allowed_methods(request: Request) -> list[str]:
    """Every method some route serves at the request's path (Starlette's 405 names only the
    first matching route's): each method is tried against the routes."""
    routes = request.app.router.routes
    return [
        method
        for method in _METHODS
        if any(route.matches({**request.scope, "method": method})[0] == Match.FULL for route in routes)
    ]


class UnexpectedErrors:
    """Outermost ASGI middleware: an exception no handler turned into an answer becomes a
    problem+json 500, logged with its traceback, and the connection stays usable. When the
    response had already started, nothing can be answered any more and the exception goes on
    (the server then closes the connection, as it must)."""

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = False

        async def tracking_send(message):
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, receive, tracking_send)
        except Exception as error:
            if started:
                raise
            logger.exception("unexpected error on %s %s", scope.get("method"), scope.get("path"))
            response = problem(500, _TITLES[500], f"an unexpected {type(error).__name__} occurred; it has been logged")
            await response(scope, receive, send)


def install_problem_handlers(app: FastAPI) -> None:
    """Route every error family of ``app`` to a problem+json answer and declare them in its
    OpenAPI. Add ``UnexpectedErrors`` as the app's last (outermost) middleware."""
    # Starlette types every handler as taking Exception; each of these takes its own class.
    app.add_exception_handler(ToptrajError, _toptraj_error)  # type: ignore[arg-type]
    app.add_exception_handler(RequestValidationError, _validation_error)  # type: ignore[arg-type]
    app.add_exception_handler(StarletteHTTPException, _http_error)  # type: ignore[arg-type]
    declare_problems(app)
