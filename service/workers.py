"""The planning workers: at most ``workers`` plannings run at once, each in a thread of its own
pool under a time budget; up to ``queue`` more wait for a thread within their budget; beyond
that a request is refused at once with 503 and ``Retry-After``.

Memory is bounded the same way: each planning is capped (grid, samples, body size) and at most
``workers`` run. A worker slot is freed when its thread really ends, not when its caller stops
waiting: after a 504 the deadline is cancelled, the thread stops at its next check (and kills any
worker process it waits on, ``toptraj.planners.execution.isolated``), and only then may the next planning start.

Waiting requests get a thread in the order they came (a request arriving while others wait
queues behind them), and the thread that frees a slot wakes the first of them at once: without
this, a fresh request could take a freed slot ahead of requests that had been waiting, which
left some of them waiting many rounds (p99 at 16 clients ten times the p50).
"""

from __future__ import annotations

import asyncio
import threading
from collections import deque
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from toptraj.planners import Deadline
from toptraj.planners.errors import BudgetExceeded
from toptraj.planners.execution.deadline import Leash, LeashSlipped
from toptraj.robots.errors import ToptrajError
from toptraj.service.budget_advice import advised


class ServiceBusy(ToptrajError):
    """Every planning worker is busy and the queue is full.

    Attributes:
        retry_after: Seconds after which a retry may find a free worker (``Retry-After``).
    """

    status = 503
    title = "Service busy"

    def __init__(self, detail: str, retry_after: int = 1):
        super().__init__(detail)
        self.retry_after = retry_after


#: How often a request waiting for a worker looks for a free one when nobody woke it, in s.
_POLL_S = 0.005


class _Waiter:
    """A request waiting for a slot: woken from any thread through its event loop."""

    def __init__(self):
        self.loop = asyncio.get_running_loop()
        self.woken = asyncio.Event()

    def wake(self) -> None:
        """Wake the waiter (from any thread); a closed event loop has nobody left to wake."""
        try:
            self.loop.call_soon_threadsafe(self.woken.set)
        except RuntimeError:
            pass


class PlanningWorkers:
    """Runs ``function(deadline)`` calls in at most ``workers`` threads, with a bounded queue.

    Args:
        workers: Plannings run at once (default in the settings: the number of cores).
        queue: Requests that may wait for a free worker; beyond, 503.
        leash_s: How long a planning that may run on the event loop is tried there, in s (see
            ``run``); 0 never tries one.
        connections: How many connections the process holds open
            (``toptraj.service.serving.open_connections``). A planning is tried on the loop only while
            it holds at most one: a loop held by a try cannot take its turn at accepting, and a
            burst of connections would then all go to the other server processes.
        label: What its workers run, in the 503's detail (``"heavy planning"`` for the lane
            of heavy plannings, ``toptraj.service.planning.heavy``).
    """

    def __init__(
        self, workers: int, queue: int, leash_s: float = 0.0, connections: Callable[[], int] = lambda: 0, label: str = "planning",
        retry_after: int = 1,
    ):
        self.workers, self.queue, self.leash_s, self.label = workers, queue, leash_s, label
        self.retry_after = retry_after  # seconds a full lane's 503 asks to wait (a heavy planning holds its worker for seconds)
        self._connections = connections
        self._executor: ThreadPoolExecutor | None = None
        # Thread primitives, not asyncio ones: a slot is freed by the planning thread itself when
        # it ends, whatever became of the event loop that started it.
        self._slots = threading.BoundedSemaphore(workers)
        self._lock = threading.Lock()
        self._admitted = 0
        self._waiting: deque[_Waiter] = deque()  # first come, first served

    async def run(self, function, budget_s: float, leashed: bool = False, advice: str = "", busy_advice: str = ""):
        """``function(deadline)`` in a worker thread; past ``budget_s`` seconds from now (waiting
        for a worker included), cancel its deadline and raise ``BudgetExceeded``, its message
        ending with ``advice`` (what the caller can do instead, ``toptraj.service.budget_advice``);
        a ``ServiceBusy`` ends with ``busy_advice`` (what else the caller can do than wait).

        With ``leashed``, when no other planning runs or waits (``_alone``), ``function`` is
        first tried on the event loop itself under a ``Leash`` of ``leash_s`` (shorter than the
        budget): a short planning is answered without the two thread hand-offs (about 0.3 ms
        of a 5 ms request), and one that runs past the leash, or sizes itself by its budget,
        slips it and runs again in a thread under what is left of the budget. The loop is held
        up by at most the leash (and the step in which it runs out), and only while the
        service is otherwise idle: under load every planning runs in a thread. ``function``
        must be free of effects beyond its answer, as it may run twice.

        Raises:
            ServiceBusy: ``workers`` plannings run and ``queue`` more wait already.
            BudgetExceeded: the budget was spent, waiting or planning.
        """
        try:
            return await self._run(function, budget_s, leashed)
        except BudgetExceeded as error:
            raise advised(error, advice) from None
        except ServiceBusy as error:
            if not busy_advice:
                raise
            raise ServiceBusy(f"{error.detail}, or {busy_advice}", error.retry_after) from None

    async def _run(self, function, budget_s: float, leashed: bool):
        """``run`` without the advice."""
        with self._lock:
            if self._admitted >= self.workers + self.queue:
                raise ServiceBusy(
                    f"all {self.workers} {self.label} workers are busy and {self.queue} requests wait already; retry "
                    + ("shortly" if self.retry_after <= 1 else f"in {self.retry_after} s"),
                    self.retry_after,
                )
            self._admitted += 1
        deadline = Deadline(budget_s)
        started = False
        try:
            if leashed and 0.0 < self.leash_s < budget_s and await self._alone():
                try:
                    return function(Leash(self.leash_s))
                except LeashSlipped:  # again in a thread, under the same deadline, if any is left
                    if deadline.remaining() == 0.0:
                        raise BudgetExceeded(f"planning exceeded its time budget of {budget_s:g} s") from None
            await self._acquire(deadline, budget_s)
            loop = asyncio.get_running_loop()
            # One future of this loop, settled by the planning thread through one callback: the
            # answer reaches the request in one turn of the loop, not a chain of wrapped futures.
            answer: asyncio.Future = loop.create_future()
            self._submit(function, deadline, loop, answer)
            started = True
            return await _awaited(answer, deadline, budget_s, loop)
        finally:
            if not started:
                with self._lock:
                    self._admitted -= 1

    def _submit(self, function, deadline: Deadline, loop: asyncio.AbstractEventLoop, answer: asyncio.Future) -> None:
        """``function(deadline)`` submitted to a planning thread (a slot already held), which
        frees its slot when it ends and settles ``answer`` with (result, error)."""

        def work():
            outcome: tuple[Any, BaseException | None]
            try:
                outcome = (function(deadline), None)
            except BaseException as error:  # delivered to the request, as an executor would
                outcome = (None, error)
            finally:
                self._release()
            try:
                loop.call_soon_threadsafe(_settle, answer, outcome)
            except RuntimeError:  # the loop closed: nobody waits for the answer
                pass

        try:
            self._threads().submit(work)
        except BaseException:
            self._slots.release()
            self._wake_first()
            raise

    async def _alone(self) -> bool:
        """Whether this request's planning is the only one admitted, on the only connection the
        process holds, once the requests that reached the server with it had their turn: one
        turn of the event loop lets them (and a ``/health`` probe among them) reach their own
        admission first, so that requests arriving together, as under load, all go to the
        threads instead of queueing behind one another on the loop."""
        if self._connections() > 1:
            return False
        await asyncio.sleep(0)
        with self._lock:
            return self._admitted == 1 and not self._waiting

    async def _acquire(self, deadline: Deadline, budget_s: float) -> None:
        """Take a slot, after every request that was waiting before this one.

        Raises:
            BudgetExceeded: the deadline passed first.
        """
        with self._lock:
            if not self._waiting and self._slots.acquire(blocking=False):
                return
            waiter = _Waiter()
            self._waiting.append(waiter)
        try:
            while True:
                with self._lock:
                    while self._waiting[0].loop.is_closed():  # its request is gone with its loop
                        self._waiting.popleft()
                    if self._waiting[0] is waiter and self._slots.acquire(blocking=False):
                        return
                remaining = deadline.remaining()
                assert remaining is not None  # a planning always runs under a budget
                if remaining <= 0.0:
                    raise BudgetExceeded(f"no planning worker came free within the time budget of {budget_s:g} s")
                try:
                    await asyncio.wait_for(waiter.woken.wait(), timeout=min(remaining, _POLL_S))
                except TimeoutError:
                    pass
                waiter.woken.clear()
        finally:
            with self._lock:
                if waiter in self._waiting:
                    self._waiting.remove(waiter)
                following = self._waiting[0] if self._waiting else None
            if following is not None:
                following.wake()  # it is first now, and a slot may be free

    def _wake_first(self) -> None:
        """Wake the request that has waited longest, if any."""
        with self._lock:
            first = self._waiting[0] if self._waiting else None
        if first is not None:
            first.wake()

    def _threads(self) -> ThreadPoolExecutor:
        """The pool of planning threads, opened on first use and again after ``close``."""
        with self._lock:
            if self._executor is None:
                self._executor = ThreadPoolExecutor(max_workers=self.workers, thread_name_prefix=f"toptraj-{self.label.replace(' ', '-')}")
            return self._executor

    def _release(self) -> None:
        """A planning thread has ended: free its slot."""
        with self._lock:
            self._admitted -= 1
        self._slots.release()
        self._wake_first()

    def close(self) -> None:
        """Let the threads go: running plannings end at their next deadline check, and the next
        planning (an app started again) opens a new pool. The slots stay shared, so threads of a
        closed pool still count against ``workers`` until they end."""
        with self._lock:
            executor, self._executor = self._executor, None
        if executor is not None:
            executor.shutdown(wait=False)


#: What the timer of ``PlanningWorkers.run`` settles a request's answer with when its budget ends.
_EXPIRED = object()


def _settle(answer: asyncio.Future, outcome) -> None:
    """Settle a request's answer with ``outcome`` (``(result, error)``, or ``_EXPIRED``) unless
    it was settled already: the first of the planning thread and the budget's timer wins, and
    an answer nobody waits for any more (a request past its budget, or gone) is dropped."""
    if not answer.done():
        answer.set_result(outcome)


async def _awaited(answer: asyncio.Future, deadline: Deadline, budget_s: float, loop: asyncio.AbstractEventLoop):
    """The planning's result once a planning thread settles ``answer``; its deadline cancelled
    and ``BudgetExceeded`` raised when the budget passes first, its deadline cancelled when the
    request is (the client went away, or the server stops)."""
    remaining = deadline.remaining()
    timer = None if remaining is None else loop.call_later(max(remaining, 0.0), _settle, answer, _EXPIRED)
    try:
        outcome = await answer
    except asyncio.CancelledError:  # the client went away, or the server stops
        deadline.cancel()
        raise
    finally:
        if timer is not None:
            timer.cancel()
    if outcome is _EXPIRED:
        deadline.cancel()
        raise BudgetExceeded(f"planning exceeded its time budget of {budget_s:g} s")
    result, error = outcome
    if error is not None:
        raise error
    return result
