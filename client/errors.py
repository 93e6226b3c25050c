"""``ProblemError``: every answer of the service that is not a success, as one exception."""

from __future__ import annotations

from typing import Any

import httpx

#: The members of an RFC 9457 problem the service fills; any other member is in ``extras``.
_KNOWN = ("type", "title", "status", "detail", "errors", "s", "joint", "limit")


class ProblemError(Exception):
    """An error answer of the service (``application/problem+json``, RFC 9457), or the error of a
    failed job or of one request of a batch, which carry the same object.

    Attributes:
        status: The HTTP status (e.g. 404 unknown robot, 422 invalid or impossible request,
            409 a job without an answer, 503 a full queue, 504 over the time budget).
        title: A short summary of the kind of problem.
        detail: What went wrong, where, and how to fix it.
        type: A URI naming the kind of problem (``about:blank``: the status says it).
        errors: For a malformed request: one ``{"field", "message"}`` per field, e.g.
            ``{"field": "path.waypoints[1][2]", "message": "..."}``; empty otherwise.
        s: Where along the path (path parameter in [0, 1]) a limit cannot be met, else None.
        joint: The joint whose limit cannot be met, else None.
        limit: The kind of limit that cannot be met (velocity, acceleration, torque, jerk),
            else None.
        extras: Any other member of the problem, by name (e.g. a new fact the service adds).
        problem: The whole problem object as the service sent it.
        retry_after: Seconds to wait before trying again (``Retry-After`` of a 503), else None.
    """

    def __init__(self, problem: dict[str, Any], retry_after: float | None = None):
        self.problem = problem
        self.status = int(problem.get("status") or 0)
        self.title = str(problem.get("title", ""))
        self.detail = str(problem.get("detail", ""))
        self.type = str(problem.get("type", "about:blank"))
        self.errors: list[dict[str, str]] = list(problem.get("errors") or [])
        s = problem.get("s")
        self.s: float | None = None if s is None else float(s)
        self.joint: str | None = problem.get("joint")
        self.limit: str | None = problem.get("limit")
        self.extras = {key: value for key, value in problem.items() if key not in _KNOWN}
        self.retry_after = retry_after
        super().__init__(f"{self.status} {self.title}: {self.detail}")

    def __reduce__(self) -> tuple:
        return (ProblemError, (self.problem, self.retry_after))

    @classmethod
    def from_response(cls, response: httpx.Response) -> ProblemError:
        """The problem an error ``response`` carries; a body that is not a problem (a proxy's
        page, say) becomes one with the response's status, reason and the start of its text."""
        try:
            problem = response.json()
        except ValueError:
            problem = None
        if not isinstance(problem, dict) or "status" not in problem:
            problem = {"status": response.status_code, "title": response.reason_phrase, "detail": response.text[:500]}
        retry_after = response.headers.get("retry-after")
        try:
            seconds = None if retry_after is None else float(retry_after)
        except ValueError:
            seconds = None
        return cls(problem, seconds)
