"""Errors as ``application/problem+json`` (RFC 9457): one handler per family, an outermost guard
for the unexpected, an encoder that refuses NaN and infinity, and the OpenAPI declaring all of it.

* ``STATUS`` gives the HTTP status of each error class of the library (``status_of``: its own
  class or nearest base in the table; the service's own errors carry theirs).
* ``install_problem_handlers`` routes the error tree (``ToptrajError``), request validation and
  Starlette's HTTP errors (404, 405 with its ``Allow`` header, ...) to problem answers.
* ``UnexpectedErrors`` (pure ASGI, outermost) answers any other exception with a problem 500
  and lets the server keep the connection: Starlette's own last-resort handler re-raises after
  answering, and uvicorn then drops the keep-alive connection without ``Connection: close``,
  so a client's next request on it fails.
* ``FiniteJSONResponse`` refuses NaN and infinity (JSON has no such numbers) with a 422 that
  says where the answer held one, instead of an encoder crash.
* ``problem_responses`` and ``declare_problems`` make the OpenAPI say what the service answers:
  problem+json bodies for 400, 404, 409, 413, 422 and 504, in place of FastAPI's default 422.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Iterable
from typing import Any

import numpy as np
from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import ValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.routing import Match

from toptraj.planners.errors import BudgetExceeded
from toptraj.robots import ToptrajError
from toptraj.robots.errors import CatalogRobotReadOnly, RobotConflict, UnknownRobot, UploadStoreFull, UploadStoreUnavailable
from toptraj.service.schemas.common import Problem

PROBLEM_JSON = "application/problem+json"
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
    extra = {key: getattr(error, key) for key in ("s", "joint", "limit", "link", "obstacle", "link_a", "link_b") if hasattr(error, key)}
    retry_after = getattr(error, "retry_after", None)
    headers = None if retry_after is None else {"Retry-After": str(retry_after)}
    return problem(status_of(error), error.title, error.detail, headers, **extra)


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


# --- OpenAPI -------------------------------------------------------------------------------

_REF = "#/components/schemas/"
_DESCRIPTIONS = {
    400: "The request body cannot be read.",
    404: "No such resource (e.g. an unknown robot).",
    409: "The name is taken.",
    413: "The request body exceeds the size cap.",
    422: "Malformed or impossible input: a field out of range, wrong lengths, NaN/inf, a path "
    "that no timing can follow (the detail says where).",
    503: "The service cannot do this now (e.g. its data directory cannot be written).",
    504: "The computation ran past its time budget.",
}
#: What every operation with a body may answer, whatever it declares (FastAPI itself adds a
#: 422 to operations with parameters; its content is replaced below).
_WITH_BODY = (400, 413, 422)


def _problem_content() -> dict:
    return {PROBLEM_JSON: {"schema": {"$ref": _REF + "Problem"}}}


def problem_responses(*statuses: int) -> dict[int | str, dict[str, Any]]:
    """``responses=`` of a route: each status answered with a problem+json body."""
    return {status: {"description": _DESCRIPTIONS[status], "content": _problem_content()} for status in statuses}


def _problem_schemas() -> dict[str, dict]:
    schema = Problem.model_json_schema(ref_template=_REF + "{model}")
    definitions = schema.pop("$defs", {})
    return {"Problem": schema, **definitions}


def _declare(openapi: dict) -> dict:
    components = openapi.setdefault("components", {}).setdefault("schemas", {})
    components.update(_problem_schemas())
    for operations in openapi.get("paths", {}).values():
        for operation in operations.values():
            if not isinstance(operation, dict) or "responses" not in operation:
                continue
            responses = operation["responses"]
            for status in _WITH_BODY if "requestBody" in operation else ():
                responses[str(status)] = problem_responses(status)[status]
            for status, response in responses.items():
                if status.isdigit() and int(status) >= 400:
                    response["content"] = _problem_content()
    for name in ("HTTPValidationError", "ValidationError"):
        if f'"{_REF}{name}"' not in json.dumps(openapi):
            components.pop(name, None)
    return openapi


def declare_problems(app: FastAPI) -> None:
    """Make ``app``'s OpenAPI declare its error answers as problem+json (``Problem``), with
    FastAPI's default 422 schema replaced."""

    def openapi() -> dict:
        return _declare(FastAPI.openapi(app))

    app.openapi = openapi  # type: ignore[method-assign]  # FastAPI's way to extend its schema
