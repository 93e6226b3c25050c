"""``GET /guide/``: the documentation site (MkDocs, built from ``docs/``), served offline.

The site is built at install time (``make guide``, run by ``make install`` and ``make serve``,
and by the Dockerfile) into ``service/web/guide/``, a git-ignored folder; ``Settings.guide_dir``
points elsewhere. Without a built site every path answers a 404 problem saying how to build it.
"""

from __future__ import annotations

import mimetypes
from pathlib import Path

from fastapi import APIRouter, HTTPException, Request
from fastapi.responses import FileResponse, RedirectResponse

from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(include_in_schema=False, route_class=StrictJSONRoute)

#: How to build the site, as the 404 of an absent one says it.
BUILD_ADVICE = (
    "the documentation site is not built: run `make guide` in the repository "
    "(or `python -m mkdocs build --strict -d service/web/guide` with the `docs` extra installed), "
    "then reload; the same pages are in docs/ as Markdown"
)
#: Media types of the site's files that ``mimetypes`` may not know on a bare system.
_TYPES = {".js": "text/javascript", ".css": "text/css", ".svg": "image/svg+xml", ".json": "application/json",
          ".inv": "application/octet-stream", ".xml": "application/xml", ".gz": "application/gzip"}
_MAX_PATH = 512


def _site(request: Request) -> Path:
    root = Path(request.app.state.settings.guide_dir).resolve()
    if not (root / "index.html").is_file():
        raise HTTPException(404, BUILD_ADVICE)
    return root


@router.get("/guide")
def guide_root() -> RedirectResponse:
    """The site's pages link relative to ``/guide/``: send the bare path there."""
    return RedirectResponse("/guide/", status_code=308)


@router.get("/guide/{path:path}")
def guide_file(path: str, request: Request) -> FileResponse:
    """A file of the built site: a folder's ``index.html``, never a file outside the site."""
    root = _site(request)
    if len(path) > _MAX_PATH:
        raise HTTPException(404, f"no page of the guide at a path of {len(path)} characters")
    target = (root / path).resolve()
    if not target.is_relative_to(root):
        raise HTTPException(404, "no page of the guide there; start at /guide/")
    if target.is_dir():
        if path and not path.endswith("/"):
            return RedirectResponse(f"/guide/{path}/", status_code=308)  # type: ignore[return-value]
        target = target / "index.html"
    if not target.is_file():
        raise HTTPException(404, f"no page of the guide at /guide/{path[:80]}; start at /guide/")
    media_type = _TYPES.get(target.suffix) or mimetypes.guess_type(target.name)[0] or "application/octet-stream"
    return FileResponse(target, media_type=media_type)
