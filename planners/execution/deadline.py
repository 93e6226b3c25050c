"""A cooperative time budget: long computations call ``check()`` between steps, and may say
how far they are with ``progress(fraction, stage)``."""

from __future__ import annotations

import copy
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from toptraj.planners.errors import BudgetExceeded

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

    @classmethod
    def ending_at(cls, end: float | None, budget_s: float | None, progress: Progress | None = None) -> Deadline:
        """A deadline that passes at ``end`` (``time.monotonic()``, the same clock in every
        process of the machine) and names ``budget_s`` when it does: the deadline of a caller,
        carried into a worker process (``toptraj.planners.execution.isolated``)."""
        deadline = cls(budget_s, progress)
        deadline._end = end
        return deadline

    @property
    def end(self) -> float | None:
        """When the budget is spent (``time.monotonic()``), or ``None`` without a budget."""
        return self._end

    def remaining(self) -> float | None:
        """Seconds left (at least 0), or ``None`` without a budget."""
        return None if self._end is None else max(0.0, self._end - time.monotonic())

    def expect(self, seconds: float) -> None:
        """Say that the next step, which does not check, takes about ``seconds``. A budget
        stops work only at its checks, so this is a no-op here; a ``Leash`` slips at once when
        the step would run past it."""

    def check(self) -> None:
        """Raise ``BudgetExceeded`` when the budget is spent or the caller cancelled."""
        if self._cancelled.is_set() or (self._end is not None and time.monotonic() > self._end):
            if self.budget_s is None:
                raise BudgetExceeded("planning was stopped by its caller", budget_s=None)
            raise BudgetExceeded(f"planning exceeded its time budget of {self.budget_s:.3g} s", budget_s=self.budget_s)

    def share(self, fraction: float) -> Deadline:
        """This deadline (the same cancellation and progress) ending once ``fraction`` of the
        seconds now remaining have passed; without a budget, the deadline itself."""
        remaining = self.remaining()
        if remaining is None:
            return self
        part = copy.copy(self)
        part._end = time.monotonic() + fraction * remaining
        return part

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


class LeashSlipped(BudgetExceeded):
    """Work tried on a ``Leash`` ran past it, or asked for what a leash cannot give: it is to
    run again on its own, under its whole budget."""


class Leash(Deadline):
    """A short deadline for trying a computation where it holds up others (a server's event
    loop): ``check()`` raises ``LeashSlipped`` once ``leash_s`` seconds have passed, and
    ``expect(seconds)`` when a step that does not check would end past them. Work that
    sizes itself by its budget (``remaining()``) or waits on work that cannot check a deadline
    (``on_cancel``, a worker process) gets ``LeashSlipped`` at once, before it starts: a leash
    is not a budget, and such work must see the budget it was given.

    Args:
        leash_s: Seconds the try may take, from construction.
    """

    def __init__(self, leash_s: float):
        super().__init__(leash_s)

    def remaining(self) -> float | None:
        """Raise ``LeashSlipped``: a leash says nothing of the budget."""
        raise LeashSlipped("work that sizes itself by its budget runs on its own")

    @contextmanager
    def on_cancel(self, stop: Callable[[], None]) -> Iterator[None]:
        """Raise ``LeashSlipped``: work that cannot check a deadline is not tried on a leash."""
        raise LeashSlipped("work that cannot check a deadline runs on its own")
        yield  # pragma: no cover - a context manager's generator

    def expect(self, seconds: float) -> None:
        """Raise ``LeashSlipped`` when a step of about ``seconds`` would end past the leash."""
        if time.monotonic() + seconds > self._end:  # type: ignore[operator]
            raise LeashSlipped(f"a step of about {seconds:.3g} s would run past the leash of {self.budget_s} s")

    def check(self) -> None:
        """Raise ``LeashSlipped`` once the leash has run out."""
        if time.monotonic() > self._end:  # type: ignore[operator]
            raise LeashSlipped(f"the try ran past its leash of {self.budget_s} s")
