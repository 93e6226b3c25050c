"""``GET /health``."""

from fastapi import APIRouter

router = APIRouter(tags=["health"])


@router.get("/health", summary="Liveness check")
async def health() -> dict[str, str]:
    """Answers `{"status": "ok"}` while the service runs, at once, however busy its planning.
    \f
    Served on the event loop itself, so that it never waits for a thread behind planning."""
    return {"status": "ok"}
