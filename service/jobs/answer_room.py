"""Room left in a batch job's answer: the job's answer is kept up to ``max_response_bytes`` (20 MB
by default), and the answers of a batch's requests are only known once planned (their samples
follow the planned duration, which no estimate before the work knows; ``output.dt`` and the
sample cap only bound each answer alone, to the same cap). So the room is counted as the answers
arrive: each request is planned as its synchronous endpoint plans it (its samples within the
cap, else its own 422 naming the ``output.dt`` that fits), and the first answer that does not fit
in what is left stops the job's planning: it and every request not yet planned get a 422 saying
from which request on to submit them again, and the job ends at once with every answer that fits.
"""

from __future__ import annotations

import orjson

from toptraj.service.batches.lines import problem_body

#: Bytes of a batch's answer kept per request for its envelope (line, status) and, should it
#: not be planned, its problem.
LINE_BYTES = 700
#: Bytes kept for the envelope of the whole answer.
ENVELOPE_BYTES = 1_000
#: Title of a request's problem when the batch's answer has no room left for it.
TITLE = "Answer too large"


class AnswerRoom:
    """What is left of a batch's answer cap while its ``count`` requests are answered."""

    def __init__(self, cap_bytes: int, count: int):
        self.cap_bytes, self.count = cap_bytes, count
        self.left = cap_bytes - ENVELOPE_BYTES - count * LINE_BYTES
        self.full_from: int | None = None  # the 0-based index of the first request not kept
        self.kept = 0  # answers kept
        self.largest = 0  # bytes of the largest answer kept, or of the one that did not fit

    def full(self) -> bool:
        """Whether an answer did not fit: no more requests are planned."""
        return self.full_from is not None

    def keep(self, index: int, status: int, body: bytes) -> tuple[int, bytes]:
        """Request ``index``'s answer when it fits (its bytes taken from the room), else its 422
        and the room marked full."""
        self.largest = max(self.largest, len(body))
        if len(body) <= self.left and self.full_from is None:
            self.left -= len(body)
            self.kept += 1
            return status, body
        self.full_from = index if self.full_from is None else min(self.full_from, index)
        return self.not_kept(index, len(body))

    def not_kept(self, index: int, size: int | None = None) -> tuple[int, bytes]:
        """The 422 of request ``index``, not planned (``size`` None) or whose answer of ``size``
        bytes did not fit."""
        if self.full_from is None:
            self.full_from = index
        what = "was not planned" if size is None else f"has {size} bytes, which do not fit"
        # as many answers as large as the largest seen as a batch's answer holds, whatever the
        # others: the number kept counts small answers too
        fit = (self.cap_bytes - ENVELOPE_BYTES) // (self.largest + LINE_BYTES) if self.largest else 0
        if fit >= 2:
            advice = f"in batches of at most {fit} requests (answers of up to {self.largest} bytes, the largest here)"
        else:
            advice = "each as a job of its own (POST /v1/jobs)"
        detail = (
            f"request {index + 1} {what}: a batch's answer holds at most {self.cap_bytes} bytes, filled by the "
            f"{self.kept} answers before; submit the requests given this 422 (from request {self.full_from + 1} on) "
            f"{advice}, or with a larger output.dt (fewer samples)"
        )
        return 422, problem_body(422, TITLE, detail)


def kept_results(answers: list[tuple[int, bytes]]) -> bytes:
    """A batch's answer (``BatchResponse``) from each request's (status, body)."""
    return orjson.dumps(
        {"results": [{"line": k + 1, "status": status, "body": orjson.Fragment(body)} for k, (status, body) in enumerate(answers)]}
    )
