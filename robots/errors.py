"""The one exception tree of toptraj, rooted here because every layer (robots, planners, service)
may raise it. Each error carries the facts a caller needs as attributes (the input's field in the
library's own names, the value given, bounds, where along the path); ``str(error)`` is one sentence
in the library's words. The service picks the HTTP status, the title and the wording of its
answers from the class and the facts (``service/errors.py``)."""

from __future__ import annotations

from typing import Any

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
    """Root of all toptraj errors. The facts of a subclass are attributes too, given as
    keywords (``field``, ``value``, ``s``, ``joint``, ...).

    Attributes:
        detail: One sentence in the library's words saying what is wrong and where (``str``).
    """

    def __init__(self, detail: str = "", **facts: Any):
        self.__dict__.update(facts)
        detail = detail or self.sentence()
        if len(detail) > MAX_DETAIL_CHARS:
            detail = detail[: MAX_DETAIL_CHARS - 20] + " ... (detail cut)"
        super().__init__(detail)
        self.detail = detail

    def sentence(self) -> str:
        """The library's sentence for an error raised with facts only (``detail`` left out)."""
        facts = ", ".join(f"{key} = {excerpt(value)}" for key, value in vars(self).items())
        return f"{type(self).__name__}: {facts}"

    def __reduce__(self) -> tuple[Any, ...]:
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


class InvalidInput(ToptrajError):
    """Input that cannot be used as given.

    Attributes:
        field: The input, in the library's own names: ``grid.intervals``, ``sampling.dt``,
            ``waypoints[2][4]``, ``limits.velocity[1]``, ``boundary.start_velocity`` (the
            service maps them to its request's fields).
        value: What was given (shown only through ``excerpt``).
        rule: The rule it breaks, a short key (``out_of_range``, ``needs_rest``, ...); further
            facts by rule, as keywords.

    ``detail``, when given, is the library's sentence (else one is made from the facts).
    """

    field: str
    value: object
    rule: str
    rule_of_class = "invalid_input"

    def __init__(self, field: str, value: object = None, *, rule: str = "", detail: str = "", **facts: Any):
        super().__init__(detail, field=field, value=value, rule=rule or self.rule_of_class, **facts)

    def sentence(self) -> str:
        """``field = value`` and the rule it breaks, with the other facts."""
        facts = ", ".join(f"{key} = {excerpt(value)}" for key, value in vars(self).items() if key not in ("field", "value", "rule"))
        return f"{self.field} = {excerpt(self.value)} breaks the rule {self.rule!r}" + (f" ({facts})" if facts else "")


class UnknownRobot(ToptrajError):
    """No robot of that name is bundled, in example-robot-data, or uploaded (``name``; the
    catalog's robots: ``known``)."""

    def __init__(self, name: str, known: list[str]):
        super().__init__(
            f"no robot named {excerpt(name)}; catalog robots: {', '.join(known)}", name=name, known=tuple(known), rule="unknown_robot"
        )


class InvalidURDF(ToptrajError):
    """An uploaded URDF that cannot be turned into a usable robot."""


class RobotConflict(ToptrajError):
    """An upload asks for a name that another robot already holds."""


class InvalidRobotName(ToptrajError):
    """A name for an upload that breaks the naming rule (length, characters)."""


class CatalogRobotReadOnly(ToptrajError):
    """A request to delete a bundled or example-robot-data robot: only uploads can be deleted."""


class UploadStoreFull(ToptrajError):
    """The upload store holds as many uploads, or as many bytes, as its caps allow."""


class UploadStoreUnavailable(ToptrajError):
    """The upload store cannot be read or written (the data directory is not writable, the disk
    is full, the database is damaged): a condition of the server, not of the request."""


class InvalidUpload(ToptrajError):
    """The options of an upload do not fit its URDF or are malformed."""


class InvalidLimits(InvalidInput):
    """A limit override of the wrong length or value."""

