"""``GET /health``."""

from fastapi import APIRouter

router = APIRouter(tags=["health"])


@router.get("/health", summary="Liveness check")
def health() -> dict[str, str]:
    """Answers ``{"status": "ok"}`` while the service runs."""
    return {"status": "ok"}
