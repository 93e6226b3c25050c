"""ASGI middleware that answers 413 to request bodies over a size cap, whether or not the client
announced a Content-Length. Past the cap the body is cut off (the app sees an end of body) and
whatever the app answers is replaced by the 413 problem."""

from __future__ import annotations

import json

#: What to do about a body over the cap (the cap is the server's ``TOPTRAJ_MAX_BODY_BYTES``).
#: The default cap on a request body, in bytes (``Settings.max_body_bytes``; ``toptraj plan`` reads no more).
DEFAULT_MAX_BODY_BYTES = 2_000_000
REMEDY = (
    "send fewer waypoints (the path is a spline through them, so a coarser list often gives the same motion), "
    "split a batch into several POST /v1/batches, or plan a large file of requests with `toptraj batch` "
    "(no body cap); the cap is the server's TOPTRAJ_MAX_BODY_BYTES"
)
#: What to do about an upload over the cap: a robot's description is no list of requests.
UPLOAD_REMEDY = (
    "leave out of the URDF what planning does not read (comments, <gazebo> and <transmission> elements, materials; "
    "meshes are referenced by file name, never inlined), and give joint_limits without comments; or raise the "
    "server's TOPTRAJ_MAX_BODY_BYTES"
)


#: What to do about a cell over the cap, and about a skeleton's configurations over it.
CELL_REMEDY = "give each arm fewer waypoints (its path is a spline through them); or raise the server's TOPTRAJ_MAX_BODY_BYTES"
SKELETON_REMEDY = "send fewer configurations in q, in several requests; or raise the server's TOPTRAJ_MAX_BODY_BYTES"


def remedy_for(path: str) -> str:
    """What to do about a body over the cap sent to ``path``."""
    path = path.rstrip("/")
    if path == "/v1/robots":
        return UPLOAD_REMEDY
    if path == "/v1/cells":
        return CELL_REMEDY
    if path.startswith("/v1/robots/") and path.endswith("/skeleton"):
        return SKELETON_REMEDY
    return REMEDY


class BodySizeLimit:
    """Wraps an ASGI app; bodies over ``max_bytes`` get a problem+json 413."""

    def __init__(self, app, max_bytes: int):
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        announced = dict(scope.get("headers") or []).get(b"content-length")
        if announced is not None and announced.isdigit() and int(announced) > self.max_bytes:
            await self._refuse(send, scope.get("path", ""))
            return
        state = {"received": 0, "too_large": False, "answered": False}

        async def limited_receive():
            if state["too_large"]:
                return {"type": "http.request", "body": b"", "more_body": False}
            message = await receive()
            if message["type"] == "http.request":
                state["received"] += len(message.get("body", b""))
                if state["received"] > self.max_bytes:
                    state["too_large"] = True
                    return {"type": "http.request", "body": b"", "more_body": False}
            return message

        async def guarded_send(message):
            if not state["too_large"]:
                await send(message)
            elif not state["answered"]:
                state["answered"] = True
                await self._refuse(send, scope.get("path", ""))

        await self.app(scope, limited_receive, guarded_send)

    async def _refuse(self, send, path: str):
        body = json.dumps(
            {
                "type": "about:blank",
                "title": "Request body too large",
                "status": 413,
                "detail": f"the request body exceeds {self.max_bytes} bytes: {remedy_for(path)}",
            }
        ).encode()
        await send(
            {
                "type": "http.response.start",
                "status": 413,
                "headers": [
                    (b"content-type", b"application/problem+json"),
                    (b"content-length", str(len(body)).encode()),
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})
