"""Errors as ``application/problem+json`` (RFC 9457): one handler per family, never a bare 500
for bad input."""

from __future__ import annotations

import logging

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from robots import ToptrajError

PROBLEM_JSON = "application/problem+json"
logger = logging.getLogger("toptraj")


def problem(status: int, title: str, detail: str, headers: dict[str, str] | None = None, **extra) -> JSONResponse:
    """A problem+json response."""
    body = {"type": "about:blank", "title": title, "status": status, "detail": detail}
    body.update({key: value for key, value in extra.items() if value is not None})
    return JSONResponse(body, status_code=status, media_type=PROBLEM_JSON, headers=headers)


#: Tags of the path union that pydantic puts in error locations: path.<tag>.<field>.
_PATH_TAGS = ("waypoints", "cartesian", "free")


def _location(loc) -> str:
    parts = [str(part) for part in loc if part not in ("body",)]
    if len(parts) > 2 and parts[0] == "path" and parts[1] in _PATH_TAGS:
        del parts[1]
    text = ""
    for part in parts:
        text += f"[{part}]" if part.isdigit() else (f".{part}" if text else part)
    return text or "body"


def _toptraj_error(request: Request, error: ToptrajError) -> JSONResponse:
    extra = {key: getattr(error, key) for key in ("s", "joint") if hasattr(error, key)}
    retry_after = getattr(error, "retry_after", None)
    headers = None if retry_after is None else {"Retry-After": str(retry_after)}
    return problem(error.status, error.title, error.detail, headers, **extra)


def _validation_error(request: Request, error: RequestValidationError) -> JSONResponse:
    errors = [
        {"field": _location(item["loc"]), "message": item["msg"]} for item in error.errors()
    ]
    detail = "; ".join(f"{item['field']}: {item['message']}" for item in errors[:5])
    if len(errors) > 5:
        detail += f"; and {len(errors) - 5} more"
    return problem(422, "Invalid request", detail, errors=errors)


def _http_error(request: Request, error: StarletteHTTPException) -> JSONResponse:
    return problem(error.status_code, _TITLES.get(error.status_code, "HTTP error"), str(error.detail))


def _unexpected(request: Request, error: Exception) -> JSONResponse:
    logger.exception("unexpected error on %s %s", request.method, request.url.path)
    return problem(500, "Internal error", f"an unexpected {type(error).__name__} occurred")


_TITLES = {400: "Bad request", 404: "Not found", 405: "Method not allowed", 413: "Request body too large"}


def install_problem_handlers(app: FastAPI) -> None:
    """Route every error family of ``app`` to a problem+json answer."""
    app.add_exception_handler(ToptrajError, _toptraj_error)
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(Exception, _unexpected)
