"""The route class of every router: a request's JSON body is read by
``toptraj.service.strict_json.loads``, so that a key given twice is a 422 naming it and its
place, where FastAPI's own reading (``json.loads``) would let the last one win silently. A
route that takes a JSON body refuses a body sent without ``Content-Type: application/json``
(curl's default is form encoding) with a 415 that says which header to send, an empty body
and a body that is no JSON with a 422 that says where the text goes wrong (line, column and
the parser's message), where FastAPI would answer that the body is no object, or name the
character offset as if it were an array index. The body's size cap
(``toptraj.service.body_limit``) and the parser's nesting limit hold as before: a body nested
deeper than the parser reads is a 400 saying how deep it nests and how deep a request may."""

from __future__ import annotations

import email.message
import json
from collections.abc import Callable, Coroutine
from typing import Any

from fastapi import Request, Response, params
from fastapi.routing import APIRoute
from starlette.exceptions import HTTPException

from toptraj.service.strict_json import (
    EMPTY_BODY,
    DuplicateKey,
    NumberTooLong,
    decode_error,
    loads,
    nesting_depth,
    refused_depth,
    too_deep,
)

#: The 415's advice.
SEND_JSON = "send the header Content-Type: application/json (curl: -H 'Content-Type: application/json')"


class BodyRefused(HTTPException):
    """A JSON body the route cannot read: answered by ``toptraj.service.errors`` with
    ``problem`` (an HTTP exception, the one kind FastAPI lets out of its reading of a body)."""

    def __init__(self, problem: dict):
        super().__init__(problem["status"], problem["detail"])
        self.problem = problem


class DuplicateKeyRefused(BodyRefused):
    """A JSON body gives a key twice in one object: a 422 naming the key and its place."""

    def __init__(self, duplicate: DuplicateKey):
        super().__init__(duplicate.problem())
        self.duplicate = duplicate


def _unreadable(message: str) -> BodyRefused:
    """The 422 of a body that is empty or no JSON, ``message`` saying where and why."""
    return BodyRefused(
        {"type": "about:blank", "title": "Invalid request", "status": 422, "detail": f"body: {message}",
         "errors": [{"field": "body", "message": message}]}
    )


def _is_json(content_type: str | None) -> bool:
    """Whether a ``Content-Type`` header names JSON (``application/json``, ``application/*+json``,
    parameters allowed), as FastAPI decides whether to read a body as JSON."""
    if not content_type:
        return False
    message = email.message.Message()
    message["content-type"] = content_type
    subtype = message.get_content_subtype()
    return message.get_content_maintype() == "application" and (subtype == "json" or subtype.endswith("+json"))


def _too_deep(depth: int) -> BodyRefused:
    """The 400 of a body nesting ``depth`` levels, more than a request may."""
    return BodyRefused({"type": "about:blank", "title": "Too deeply nested", "status": 400, "detail": f"the body {too_deep(depth)}"})


class StrictJSONRequest(Request):
    """A request whose ``json()`` refuses a key given twice and says where a text that is no
    JSON goes wrong."""

    async def json(self) -> Any:
        if not hasattr(self, "_json"):
            body = await self.body()
            try:
                text = body.decode("utf-8-sig")  # JSON between systems is UTF-8 (RFC 8259, section 8.1); a BOM is ignored
            except UnicodeDecodeError:
                raise _unreadable("the body is not UTF-8 text; send JSON encoded as UTF-8") from None
            depth = refused_depth(body)
            if depth is not None:
                raise _too_deep(depth)
            try:
                self._json = loads(text)
            except DuplicateKey as duplicate:
                raise DuplicateKeyRefused(duplicate) from None
            except json.JSONDecodeError as error:
                raise _unreadable(decode_error(error)) from None
            except NumberTooLong as error:
                raise _unreadable(str(error)) from None
            except RecursionError:  # never with the depth counted above; kept as the same answer
                raise _too_deep(nesting_depth(body)) from None
        return self._json


class StrictJSONRoute(APIRoute):
    """An ``APIRoute`` whose handler reads the body as a ``StrictJSONRequest``; a route with a
    JSON body first checks the ``Content-Type`` (415) and that the body is not empty (422)."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()
        takes_json = self.body_field is not None and not isinstance(self.body_field.field_info, params.Form)

        async def strict_handler(request: Request) -> Response:
            strict = StrictJSONRequest(request.scope, request.receive, request._send)
            if takes_json:
                body = await strict.body()
                if not body.strip():
                    raise _unreadable(EMPTY_BODY)
                if not _is_json(strict.headers.get("content-type")):
                    raise BodyRefused(
                        {"type": "about:blank", "title": "Unsupported media type", "status": 415, "detail": SEND_JSON}
                    )
            return await handler(strict)

        return strict_handler
