"""Notes that go with an answer (a dropped waypoint, a corner not blended, an accuracy above
its target): the library's sentence, the rule it reports and its facts, which the service words
in its request's vocabulary, as it words errors (``service/errors.py``)."""

from __future__ import annotations

from typing import Any


class Note(str):
    """A note: ``str(note)`` is the library's sentence; ``rule`` names what it reports and
    ``facts`` hold the numbers and names it is about (fields in the library's own names, as
    ``toptraj.robots.errors.InvalidInput.field``). A ``str``, so that every reader of notes keeps
    working."""

    rule: str
    facts: dict[str, Any]

    def __new__(cls, text: str, rule: str, **facts: Any) -> Note:
        note = super().__new__(cls, text)
        note.rule = rule
        note.facts = facts
        return note

    def __getnewargs_ex__(self) -> tuple[tuple[str, str], dict[str, Any]]:
        """Pickled with its rule and facts (a worker process's notes reach the caller whole)."""
        return (str(self), self.rule), self.facts
