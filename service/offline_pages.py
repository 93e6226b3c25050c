"""ASGI middleware that keeps ``/redoc`` from reaching outside the service: ReDoc's script (served
from the installed wheel, ``fastapi-offline``) draws a "powered by" logo from its vendor's CDN in
its footer. A Content-Security-Policy allowing images from the service only makes the browser
leave that request out (the footer shows its text), so the page works offline and asks nothing
of other hosts."""

from __future__ import annotations

#: The paths whose answers carry the policy.
PAGES = frozenset({"/redoc"})
#: Images from the service itself (and the data and blob URLs a page builds), nothing else.
POLICY = (b"content-security-policy", b"img-src 'self' data: blob:")


class OwnImagesOnly:
    """Wraps an ASGI app; the answers of ``PAGES`` get ``POLICY``."""

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http" or scope.get("path") not in PAGES:
            await self.app(scope, receive, send)
            return

        async def with_policy(message):
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), POLICY]}
            await send(message)

        await self.app(scope, receive, with_policy)
