"""``GET /``: the web page, and its static files under ``/static/web/`` (``service/web``), with
Plotly's JavaScript from the installed ``plotly`` wheel."""

from __future__ import annotations

from importlib import resources

from fastapi import APIRouter, HTTPException
from fastapi.responses import FileResponse, HTMLResponse

from toptraj.service.strict_routes import StrictJSONRoute
from toptraj.service.web import STATIC

router = APIRouter(include_in_schema=False, route_class=StrictJSONRoute)

#: Files of the page, by the name it loads them under, and their media types.
_FILES = {
    "app.js": "text/javascript",
    "cell.js": "text/javascript",
    "draw.js": "text/javascript",
    "exports.js": "text/javascript",
    "style.css": "text/css",
}
_CACHE = {"Cache-Control": "public, max-age=3600"}


@router.get("/", response_class=HTMLResponse)
def page() -> FileResponse:
    return FileResponse(STATIC / "index.html", media_type="text/html")


@router.get("/static/web/plotly.min.js")
def plotly_js() -> FileResponse:
    path = resources.files("plotly") / "package_data" / "plotly.min.js"
    return FileResponse(str(path), media_type="text/javascript", headers=_CACHE)


@router.get("/static/web/{name}")
def static_file(name: str) -> FileResponse:
    if name not in _FILES:
        raise HTTPException(404, f"no file {name!r} here")
    return FileResponse(STATIC / name, media_type=_FILES[name])
