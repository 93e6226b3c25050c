"""The route class of every router: a request's JSON body is read by
``toptraj.service.strict_json.loads``, so that a key given twice is a 422 naming it and its
place, where FastAPI's own reading (``json.loads``) would let the last one win silently. The
body's size cap (``toptraj.service.body_limit``) and the parser's nesting limit (a 400) hold as
before."""

from __future__ import annotations

from collections.abc import Callable, Coroutine
from typing import Any

from fastapi import Request, Response
from fastapi.routing import APIRoute
from starlette.exceptions import HTTPException

from toptraj.service.strict_json import DuplicateKey, loads


class DuplicateKeyRefused(HTTPException):
    """A JSON body gives a key twice in one object: answered 422 by
    ``toptraj.service.errors`` (an HTTP exception, the one kind FastAPI lets out of its reading
    of a body)."""

    def __init__(self, duplicate: DuplicateKey):
        super().__init__(422, str(duplicate))
        self.duplicate = duplicate


class StrictJSONRequest(Request):
    """A request whose ``json()`` refuses a key given twice."""

    async def json(self) -> Any:
        if not hasattr(self, "_json"):
            try:
                self._json = loads(await self.body())
            except DuplicateKey as duplicate:
                raise DuplicateKeyRefused(duplicate) from None
        return self._json


class StrictJSONRoute(APIRoute):
    """An ``APIRoute`` whose handler reads the body as a ``StrictJSONRequest``."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def strict_handler(request: Request) -> Response:
            return await handler(StrictJSONRequest(request.scope, request.receive, request._send))

        return strict_handler
