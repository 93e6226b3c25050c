"""Errors as ``application/problem+json`` (RFC 9457): the status, title and words of each
error, one handler per family and an outermost guard for the unexpected.

* ``toptraj.service.problems`` gives the status, title and words of each error (framework-free:
  the CLI, jobs and batches use it too).
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

import difflib
import logging

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.routing import Match

from toptraj.robots import ToptrajError
from toptraj.service.problem_docs import PROBLEM_JSON, declare_problems
from toptraj.service.problems import HTTP_TITLES, detail, problem_facts, status_of, title_of, validation_detail, validation_errors
from toptraj.service.strict_routes import BodyRefused

logger = logging.getLogger("toptraj")


def problem(status: int, title: str, detail: str, headers: dict[str, str] | None = None, **extra) -> JSONResponse:
    """A problem+json response."""
    body = {"type": "about:blank", "title": title, "status": status, "detail": detail}
    body.update({key: value for key, value in extra.items() if value is not None})
    return JSONResponse(body, status_code=status, media_type=PROBLEM_JSON, headers=headers)


def _toptraj_error(request: Request, error: ToptrajError) -> JSONResponse:
    extra = problem_facts(error)
    retry_after = getattr(error, "retry_after", None)
    headers = None if retry_after is None else {"Retry-After": str(retry_after)}
    return problem(status_of(error), title_of(error), detail(error), headers, **extra)


def _validation_error(request: Request, error: RequestValidationError) -> JSONResponse:
    body_field = getattr(request.scope.get("route"), "body_field", None)
    model = getattr(getattr(body_field, "field_info", None), "annotation", None)
    errors, count = validation_errors(error.errors(), model)
    return problem(422, "Invalid request", validation_detail(errors, count), errors=errors)


def _body_refused(request: Request, error: BodyRefused) -> JSONResponse:
    return JSONResponse(error.problem, status_code=error.status_code, media_type=PROBLEM_JSON)


def _http_error(request: Request, error: StarletteHTTPException) -> JSONResponse:
    headers = None if error.headers is None else dict(error.headers)
    if error.status_code == 405:
        allowed = _allowed_methods(request)
        headers = {**(headers or {}), "Allow": ", ".join(allowed)}
        detail = f"{request.method} is not allowed on {request.url.path}; use {' or '.join(allowed)}"
    elif error.status_code == 404 and error.detail == "Not Found":  # no route at the path
        detail = _no_route(request)
    else:
        detail = str(error.detail)
    return problem(error.status_code, HTTP_TITLES.get(error.status_code, "HTTP error"), detail, headers=headers)


_METHODS = ("DELETE", "GET", "HEAD", "PATCH", "POST", "PUT")
#: Least similarity (difflib's ratio) of a path to a route's for "did you mean".
_CLOSE_ROUTE = 0.8


def _paths(route: object) -> list[str]:
    """The path of ``route``, or of each route of an included router (FastAPI keeps those as
    one entry whose candidates are its routes)."""
    if isinstance(path := getattr(route, "path", None), str):
        return [path]
    candidates = getattr(route, "effective_candidates", None)
    return [path for candidate in (candidates() if callable(candidates) else []) if isinstance(path := getattr(candidate, "path", None), str)]


def _no_route(request: Request) -> str:
    """The 404 of a path no route serves, with the route path most like it (``/v1/trajectory``:
    did you mean /v1/trajectories?)."""
    path = request.url.path
    routes = [path for route in request.app.router.routes for path in _paths(route)]
    close = difflib.get_close_matches(path, routes, n=1, cutoff=_CLOSE_ROUTE)
    return f"no route at {path[:200]}" + (f": did you mean {close[0]}?" if close else "") + "; the routes are listed at /docs"


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
            response = problem(500, HTTP_TITLES[500], f"an unexpected {type(error).__name__} occurred; it has been logged")
            await response(scope, receive, send)


def install_problem_handlers(app: FastAPI) -> None:
    """Route every error family of ``app`` to a problem+json answer and declare them in its
    OpenAPI. Add ``UnexpectedErrors`` as the app's last (outermost) middleware."""
    # Starlette types every handler as taking Exception; each of these takes its own class.
    app.add_exception_handler(ToptrajError, _toptraj_error)  # type: ignore[arg-type]
    app.add_exception_handler(RequestValidationError, _validation_error)  # type: ignore[arg-type]
    app.add_exception_handler(StarletteHTTPException, _http_error)  # type: ignore[arg-type]
    app.add_exception_handler(BodyRefused, _body_refused)  # type: ignore[arg-type]
    declare_problems(app)
