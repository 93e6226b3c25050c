"""A cooperative time budget: long computations call ``check()`` between steps, and may say
how far they are with ``progress(fraction, stage)``."""

from __future__ import annotations

import copy
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from planners.errors import BudgetExceeded

#: ``progress(fraction, stage)``: fraction of the work done, in [0, 1], and what is under way.
Progress = Callable[[float, str], None]


def _ignore(fraction: float, stage: str) -> None:
    """The default progress report: nobody listens."""


class Deadline:
    """Raises ``BudgetExceeded`` from ``check()`` once ``budget_s`` seconds have passed since
    construction, or as soon as ``cancel()`` was called (by a caller that stopped waiting).
    Work that cannot check it (a child process) registers how to stop it (``on_cancel``), and
    ``cancel()`` stops it at once, in the caller's thread.

    Attributes:
        progress: ``progress(fraction, stage)`` reports how far the computation is (fraction in
            [0, 1], a short stage text such as ``"collocation: guess 3 of 15"``); a no-op
            unless a listener was given. Computations report without knowing who listens.
    """

    def __init__(self, budget_s: float | None = None, progress: Progress | None = None):
        self.budget_s = budget_s
        self._end = None if budget_s is None else time.monotonic() + budget_s
        self._cancelled = threading.Event()
        # Shared with the parts made by ``within`` (shallow copies), as the event is.
        self._stoppers: list[Callable[[], None]] = []
        self._stoppers_lock = threading.Lock()
        self.progress: Progress = progress or _ignore

    def cancel(self) -> None:
        """Make the next ``check()`` raise, and stop the work registered with ``on_cancel``."""
        self._cancelled.set()
        with self._stoppers_lock:
            stoppers = list(self._stoppers)
        for stop in stoppers:
            try:
                stop()
            except Exception:  # noqa: BLE001 - the work's own check stops it anyway
                pass

    @contextmanager
    def on_cancel(self, stop: Callable[[], None]) -> Iterator[None]:
        """While in this context, ``cancel()`` calls ``stop()`` (from the cancelling thread);
        called at once when the deadline was cancelled already."""
        with self._stoppers_lock:
            self._stoppers.append(stop)
        try:
            if self._cancelled.is_set():
                stop()
            yield
        finally:
            with self._stoppers_lock:
                self._stoppers.remove(stop)

    def remaining(self) -> float | None:
        """Seconds left (at least 0), or ``None`` without a budget."""
        return None if self._end is None else max(0.0, self._end - time.monotonic())

    def check(self) -> None:
        """Raise ``BudgetExceeded`` when the budget is spent or the caller cancelled."""
        if self._cancelled.is_set() or (self._end is not None and time.monotonic() > self._end):
            raise BudgetExceeded(f"planning exceeded its time budget of {self.budget_s} s")

    def within(self, start: float, end: float, label: str = "") -> Deadline:
        """This deadline (the same end, the same cancellation) for a part of the work spanning
        the fractions [start, end] of the whole: its ``progress(f, stage)`` reports
        ``start + f (end - start)``, and ``"label: stage"`` when a label is given. Without a
        listener, the deadline itself."""
        if self.progress is _ignore:
            return self
        part = copy.copy(self)
        outer = self.progress

        def progress(fraction: float, stage: str) -> None:
            outer(start + (end - start) * min(max(fraction, 0.0), 1.0), f"{label}: {stage}" if label else stage)

        part.progress = progress
        return part


NO_DEADLINE = Deadline()
