"""The one exception tree of toptraj, rooted here because every layer (robots, planners, service)
may raise it. Each subclass carries the facts a caller needs; the service turns them into
``application/problem+json`` answers in one handler (``service/errors.py``)."""

from __future__ import annotations


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
        super().__init__(detail)
        self.detail = detail


class UnknownRobot(ToptrajError):
    """No robot of that name is bundled, in example-robot-data, or uploaded."""

    status = 404
    title = "Unknown robot"

    def __init__(self, name: str, known: list[str]):
        super().__init__(f"no robot named {name!r}; known robots: {', '.join(known)}")
        self.name = name


class InvalidURDF(ToptrajError):
    """An uploaded URDF that cannot be turned into a usable robot."""

    title = "Invalid URDF"


class RobotConflict(ToptrajError):
    """An upload asks for a name that another robot already holds."""

    status = 409
    title = "Robot name taken"


class InvalidLimits(ToptrajError):
    """A limit override of the wrong length or value."""

    title = "Invalid limits"
