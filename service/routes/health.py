"""``GET /health``."""

from fastapi import APIRouter

from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(tags=["health"], route_class=StrictJSONRoute)


@router.get("/health", summary="Liveness check")
async def health() -> dict[str, str]:
    """Answers `{"status": "ok"}` while the service runs, at once, however busy its planning.
    \f
    Served on the event loop itself, so that it never waits for a thread behind planning."""
    return {"status": "ok"}
