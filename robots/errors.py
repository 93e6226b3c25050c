"""The one exception tree of toptraj, rooted here because every layer (robots, planners, service)
may raise it. Each subclass carries the facts a caller needs; the service turns them into
``application/problem+json`` answers in one handler (``service/errors.py``)."""

from __future__ import annotations

#: Longest ``detail`` an error carries; longer sentences are cut (a detail never echoes a large
#: request back).
MAX_DETAIL_CHARS = 2_000


def excerpt(value: object, limit: int = 60) -> str:
    """``repr(value)`` cut to about ``limit`` characters, saying how long the whole was: names
    and values from a request appear in messages only this way."""
    text = repr(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... ({len(str(value))} characters)"


class ToptrajError(Exception):
    """Root of all toptraj errors.

    Attributes:
        detail: Human-readable sentence saying what is wrong and where.
        status: The HTTP status the service answers with.
        title: Short summary shared by all errors of the class.
    """

    status: int = 422
    title: str = "Unprocessable request"

    def __init__(self, detail: str):
        if len(detail) > MAX_DETAIL_CHARS:
            detail = detail[: MAX_DETAIL_CHARS - 20] + " ... (detail cut)"
        super().__init__(detail)
        self.detail = detail


class UnknownRobot(ToptrajError):
    """No robot of that name is bundled, in example-robot-data, or uploaded."""

    status = 404
    title = "Unknown robot"

    def __init__(self, name: str, known: list[str]):
        super().__init__(
            f"no robot named {excerpt(name)}; catalog robots: {', '.join(known)}; "
            "uploaded robots are listed by GET /v1/robots"
        )
        self.name = name


class InvalidURDF(ToptrajError):
    """An uploaded URDF that cannot be turned into a usable robot."""

    title = "Invalid URDF"


class RobotConflict(ToptrajError):
    """An upload asks for a name that another robot already holds."""

    status = 409
    title = "Robot name taken"


class InvalidRobotName(ToptrajError):
    """A name for an upload that breaks the naming rule (length, characters)."""

    title = "Invalid robot name"


class CatalogRobotReadOnly(ToptrajError):
    """A request to delete a bundled or example-robot-data robot: only uploads can be deleted."""

    status = 409
    title = "Catalog robot cannot be deleted"


class UploadStoreFull(ToptrajError):
    """The upload store holds as many uploads, or as many bytes, as its caps allow."""

    status = 409
    title = "Upload store full"


class UploadStoreUnavailable(ToptrajError):
    """The upload store cannot be read or written (the data directory is not writable, the disk
    is full, the database is damaged): a condition of the server, not of the request."""

    status = 503
    title = "Upload store unavailable"


class InvalidLimits(ToptrajError):
    """A limit override of the wrong length or value."""

    title = "Invalid limits"
