"""The one exception tree of toptraj, rooted here because every layer (robots, planners, service)
may raise it. Each subclass carries the facts a caller needs; the service turns them into
``application/problem+json`` answers in one handler (``service/errors.py``)."""

from __future__ import annotations

#: Longest ``detail`` an error carries; longer sentences are cut (a detail never echoes a large
#: request back).
MAX_DETAIL_CHARS = 2_000


def excerpt(value: object, limit: int = 60) -> str:
    """``value`` as a message shows it, in about ``limit`` characters whatever its size: a
    string or bytes as the ``repr`` of its first characters and how long the whole is, an
    integer of more than 30 digits by its number of digits, a list or mapping by its type and
    length (never its items, which may nest or repeat without end, as YAML aliases do), a
    number, boolean or ``None`` as its ``repr``, anything else by its type. Names and values
    from a request or an uploaded file appear in messages only this way."""
    if isinstance(value, str | bytes):
        text = repr(value[: limit + 1])
        if len(value) <= limit and len(text) <= limit + 3:
            return text
        return f"{text[:limit]}... ({len(value)} {'characters' if isinstance(value, str) else 'bytes'})"
    if isinstance(value, bool) or value is None or isinstance(value, float):
        return repr(value)
    if isinstance(value, int):
        if value.bit_length() <= 99:  # at most 30 digits
            return repr(value)
        return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    if isinstance(value, list | tuple | set | frozenset | dict):
        count = len(value)
        noun = "mapping" if isinstance(value, dict) else type(value).__name__
        items = "key" if isinstance(value, dict) else "item"
        return f"a {noun} of {count} {items}{'' if count == 1 else 's'}"
    return f"a value of type {type(value).__name__}"


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

    def __reduce__(self):
        """Pickled with its attributes, without calling ``__init__`` again: an error raised in
        a worker process (``toptraj.planners.execution.isolated``) reaches its caller whole, whatever the
        subclass's constructor takes (``Exception``'s own pickling calls ``cls(*args)``, which
        fails for a constructor with more required arguments than ``detail``)."""
        return _restore_error, (type(self), self.args, self.__dict__.copy())


def _restore_error(cls: type[ToptrajError], args: tuple, state: dict) -> ToptrajError:
    """The unpickled ``ToptrajError`` (``ToptrajError.__reduce__``)."""
    error = cls.__new__(cls, *args)
    error.args = args
    error.__dict__.update(state)
    return error


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
