"""Answers that JSON can carry: ``FiniteJSONResponse`` refuses NaN and infinity (JSON has no
such numbers) with a ``NonFiniteAnswer`` (422) that says where the answer held one, instead of
an encoder crash or invalid JSON."""

from __future__ import annotations

import json
from typing import Any

from fastapi.responses import JSONResponse

from toptraj.service.problems import non_finite_answer


class FiniteJSONResponse(JSONResponse):
    """JSON that never carries NaN or infinity: such a number is a ``NonFiniteAnswer`` (422)
    naming where it is, never invalid JSON and never an encoder crash."""

    def render(self, content: Any) -> bytes:
        try:
            return json.dumps(content, ensure_ascii=False, allow_nan=False, separators=(",", ":")).encode("utf-8")
        except ValueError:
            error = non_finite_answer(content)
            if error is None:
                raise
            raise error from None
