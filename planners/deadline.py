"""A cooperative time budget: long computations call ``check()`` between steps."""

from __future__ import annotations

import threading
import time

from planners.errors import BudgetExceeded


class Deadline:
    """Raises ``BudgetExceeded`` from ``check()`` once ``budget_s`` seconds have passed since
    construction, or as soon as ``cancel()`` was called (by a caller that stopped waiting)."""

    def __init__(self, budget_s: float | None = None):
        self.budget_s = budget_s
        self._end = None if budget_s is None else time.monotonic() + budget_s
        self._cancelled = threading.Event()

    def cancel(self) -> None:
        """Make the next ``check()`` raise."""
        self._cancelled.set()

    def remaining(self) -> float | None:
        """Seconds left (at least 0), or ``None`` without a budget."""
        return None if self._end is None else max(0.0, self._end - time.monotonic())

    def check(self) -> None:
        """Raise ``BudgetExceeded`` when the budget is spent or the caller cancelled."""
        if self._cancelled.is_set() or (self._end is not None and time.monotonic() > self._end):
            raise BudgetExceeded(f"planning exceeded its time budget of {self.budget_s} s")


NO_DEADLINE = Deadline()
