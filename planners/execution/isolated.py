"""Computations that cannot check a deadline themselves (a convex solver, an SQP step) run in a
child process that is killed when the deadline passes.

``run_isolated(function, *args, deadline=...)`` starts a child process, calls
``function(*args)`` there and returns its result; the calling thread waits on a pipe and checks
``deadline`` every ``POLL_S`` seconds, and once the deadline passes the child is killed and
``BudgetExceeded`` raised. A cancelled deadline kills the child at once, from the cancelling
thread (``Deadline.on_cancel``). The function must be a module-level function and its
arguments and result plain picklable data (numpy arrays, dataclasses of them, a ``Robot``), never
closures. The memory the child used goes back to the system when it exits. Without a deadline
(``NO_DEADLINE``, the library's default) the function runs in the calling thread: there is
nothing to stop it for. A call made inside a worker process (a job's) runs inline too: the
worker is killed as a whole (its ``memory_bytes`` holds for the call).

With ``memory_bytes``, the child's address space may grow by at most that many bytes beyond what
it holds when it starts (``RLIMIT_AS``): work that would need more gets ``MemoryError`` there,
answered as ``OverMemory``, never the system killing a process for memory. With ``nice``, the
child runs at that lower CPU priority (``os.nice``), so that the server's short requests keep
their latency while it computes.

A child ends as soon as its caller is gone, even one killed outright (``_end_with_caller``).

With ``progress=True`` the function is called with a keyword ``progress``, a callable
``progress(fraction, stage)`` whose reports reach ``deadline.progress`` in the caller (over the
pipe, at most every ``PROGRESS_S`` seconds unless the stage changes).

Children are forked from a fork server (``multiprocessing``'s ``forkserver`` context): a clean,
single-threaded process started once, which has imported the solver stacks (``PRELOAD``), so a
child starts in milliseconds without copying the threads of the server. Where ``forkserver`` is
not available, children are spawned (a fresh interpreter each). A child keeps to one BLAS
thread (``toptraj.planners.execution.threads``). As with any ``multiprocessing``
code, a script that plans with a deadline must guard its entry point with
``if __name__ == "__main__":`` (a child imports the main script as ``__mp_main__``).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import resource
import select
import signal
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

from toptraj.planners.errors import OverMemory, TimingFailed, WorkerStopped
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.execution.threads import single_blas_thread

#: Seconds between two deadline checks while waiting for the child.
POLL_S = 0.02
#: Shortest interval between two progress reports of one stage sent by a child, in s.
PROGRESS_S = 0.1
#: How much lower the CPU priority of a heavy planning's worker process is (``nice``): it
#: shares the cores with a server's short requests, which keep theirs.
LOW_PRIORITY = 5
#: Modules the fork server imports once, so that children start with them loaded: the stacks of
#: the computations that run in children, which their modules import only where they run
#: (``min_cost``: cvxpy and Clarabel; the collocation: casadi and scipy's optimizers; the
#: search: scipy's sparse graphs, optimizers and B-splines), and the compiled kernels the
#: collocation's first guess calls (``collocation.warm``: each worker would otherwise load them
#: from numba's disk cache itself, 0.36 s a ur5 free motion) and those of a small search and its
#: local optimization (``search.warm``: 0.3 to 0.9 s a search), and those of a path timed through
#: the runner, as every search's answer is (``runner.warm``). The server process imports none.
PRELOAD = [
    "numpy",
    "threadpoolctl",
    "pinocchio",
    "scipy.optimize",
    "scipy.sparse.csgraph",
    "scipy.interpolate",
    "cvxpy",
    "clarabel",
    "toptraj.planners.timing.min_cost",
    "toptraj.planners.generators.collocation.collocation",
    "toptraj.planners.generators.collocation.sparse",
    "toptraj.planners.generators.search.generator",
    "toptraj.planners.generators.collocation.warm",
    "toptraj.planners.generators.search.warm",
    "toptraj.planners.runner.warm",
]

_context: multiprocessing.context.BaseContext | None = None
_lock = threading.Lock()
#: True in a worker process: calls nested in it run inline (the whole process is killed).
_in_worker = False


#: numpy's transparent huge pages in the workers (``NUMPY_MADVISE_HUGEPAGE``), unless set: off. A
#: worker lives for one computation and touches its large arrays once, where faulting in 2 MB
#: pages costs more than their fewer TLB misses save: a search's build in a fresh worker took
#: 2.9 and 3.8 s with them against 1.5 and 2.0 s without (ur5 and panda around a box,
#: ``benchmarks/search_speed.py``, alternating), the answers unchanged.
WORKER_HUGEPAGES = "0"


def _get_context():
    global _context
    with _lock:
        if _context is None:
            # read by numpy as the fork server imports it; the server's own numpy is unchanged
            os.environ.setdefault("NUMPY_MADVISE_HUGEPAGE", WORKER_HUGEPAGES)
            if "forkserver" in multiprocessing.get_all_start_methods():
                forkserver = multiprocessing.get_context("forkserver")
                forkserver.set_forkserver_preload(PRELOAD)
                _context = forkserver
            else:
                _context = multiprocessing.get_context("spawn")
        return _context


def in_worker() -> bool:
    """Whether this process is a worker (a job's, a child's): its calls run inline, the whole
    process being killed when its work runs over."""
    return _in_worker


def run_inline_here() -> None:
    """Make every later call of this process run inline, as in a job's worker: for a process
    that is itself killed as a whole when its work runs over (a batch's Ray worker, stopped by
    its driver past the lines' budgets). A child per call would only add its start there: a
    fork server per worker importing the solver stacks, and a fork and a copy of the arguments
    per call, measured at 1.6 to 10 s per ``min_cost`` line in a Ray worker on a busy 2-core
    machine against 0.8 s inline."""
    global _in_worker
    _in_worker = True


def start_worker_server(preload: Sequence[str] = ()) -> None:
    """Start the fork server now, so that it imports ``PRELOAD`` and ``preload`` (a second or
    two, in its own process) while the service starts, rather than during the first isolated
    call. A fork server already running keeps what it imported."""
    context = _get_context()
    if context.get_start_method() == "forkserver":
        from multiprocessing import forkserver

        context.set_forkserver_preload([*PRELOAD, *preload])
        forkserver.ensure_running()


class _PipeProgress:
    """``progress(fraction, stage)`` in a child: sent to the parent, throttled per stage."""

    def __init__(self, connection) -> None:
        self._connection = connection
        self._stage: str | None = None
        self._sent = 0.0

    def __call__(self, fraction: float, stage: str) -> None:
        now = time.monotonic()
        if stage == self._stage and now - self._sent < PROGRESS_S:
            return
        self._stage, self._sent = stage, now
        self._connection.send(("progress", (float(fraction), str(stage))))


def _end_with_caller(connection) -> None:
    """End this worker as soon as the process waiting for its answer is gone, even one killed
    outright: a worker must not compute on for nobody.

    * The kernel kills it when its parent ends (Linux ``PR_SET_PDEATHSIG``): the service itself
      when spawned, else the fork server, which ends with the service once no worker holds its
      "alive" pipe open (multiprocessing gives every child a copy, for forking further; a
      worker never does, so it closes it). This needs no Python code to run, so it works
      even while a solver holds the interpreter lock for seconds.
    * Elsewhere, a thread waits (without polling) for the read end of the answer's pipe to
      close, which the kernel reports on the write end, and ends the process.
    """
    from multiprocessing import forkserver

    alive = getattr(forkserver._forkserver, "_forkserver_alive_fd", None)
    if alive is not None:
        os.close(alive)
        setattr(forkserver._forkserver, "_forkserver_alive_fd", None)  # noqa: B010 - a private attribute
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux
        pass
    if not hasattr(select, "poll"):
        return
    poller = select.poll()
    poller.register(connection.fileno(), select.POLLERR)

    def watch() -> None:
        while True:
            for _, event in poller.poll():
                if event & select.POLLNVAL:  # this worker closed the pipe itself: done
                    return
                if event & (select.POLLERR | select.POLLHUP):
                    os._exit(1)

    threading.Thread(target=watch, name="toptraj-caller-watch", daemon=True).start()


def _address_space() -> int:
    """Bytes of address space this process holds (``VmSize``), or 0 where unknown."""
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _limit_memory(memory_bytes: int) -> bool:
    """Let this process's address space grow by at most ``memory_bytes``; whether it could."""
    held = _address_space()
    if not held:
        return False
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    soft = held + memory_bytes if hard == resource.RLIM_INFINITY else min(held + memory_bytes, hard)
    try:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    except (ValueError, OSError):
        return False
    return True


def _child(connection, function, args, progress: bool, memory_bytes: int | None = None, nice: int = 0) -> None:
    global _in_worker
    _in_worker = True
    _end_with_caller(connection)
    single_blas_thread()
    if nice:
        os.nice(nice)
    limited = memory_bytes is not None and _limit_memory(memory_bytes)
    try:
        kwargs = {"progress": _PipeProgress(connection)} if progress else {}
        outcome = ("result", function(*args, **kwargs))
    except MemoryError:
        # the allowance is what the work's estimate said it needs, with room to spare: an
        # estimate too low is this clear error, not the system killing a process
        if limited:  # room to answer
            hard = resource.getrlimit(resource.RLIMIT_AS)[1]
            resource.setrlimit(resource.RLIMIT_AS, (hard, hard))
        allowance = f" of {memory_bytes / 2**30:.3g} GiB" if memory_bytes is not None else ""
        outcome = ("error", OverMemory(f"the computation ran out of its memory allowance{allowance}: ask for a smaller problem"))
    except Exception as error:  # returned to the parent, which raises it
        outcome = ("error", error)
    try:
        connection.send(outcome)
    except Exception as error:  # an unpicklable result or error
        connection.send(("error", TimingFailed(f"the worker process could not return its answer: {error!r}")))
    finally:
        connection.close()


def _inline_within(memory_bytes: int, function, *args, **kwargs):
    """``function(*args, **kwargs)`` in this process (a job's worker), its address space
    allowed to grow by ``memory_bytes`` for this call only."""
    before = resource.getrlimit(resource.RLIMIT_AS)
    limited = _limit_memory(memory_bytes)
    try:
        return function(*args, **kwargs)
    except MemoryError:
        if not limited:
            raise
        resource.setrlimit(resource.RLIMIT_AS, before)
        raise OverMemory(f"the computation ran out of its memory allowance of {memory_bytes / 2**30:.3g} GiB: ask for a smaller problem") from None
    finally:
        if limited:
            resource.setrlimit(resource.RLIMIT_AS, before)


def run_isolated(
    function: Callable[..., Any], *args: Any, deadline: Deadline = NO_DEADLINE, progress: bool = False,
    memory_bytes: int | None = None, nice: int = 0, inline: bool = False,
) -> Any:
    """``function(*args)`` computed in a child process, killed once ``deadline`` passes; with
    ``progress``, ``function(*args, progress=report)``, its reports relayed to
    ``deadline.progress``. ``memory_bytes``: the most the child's address space may grow;
    ``nice``: how much lower its CPU priority is (both ignored where it runs inline).
    ``inline``: run in the calling thread whatever the deadline (the caller decided that
    nothing needs stopping from outside: ``toptraj.planners.problem.methods.Execution``).

    Raises:
        OverMemory: the child needed more than ``memory_bytes``.
        BudgetExceeded: the deadline passed or was cancelled (the child is killed first).
        WorkerStopped: the child died without an answer (e.g. killed by the system for memory).
        Whatever ``function`` raised, re-raised here.
    """
    if inline or deadline is NO_DEADLINE or _in_worker:
        kwargs = {"progress": deadline.progress} if progress else {}
        if not (_in_worker and memory_bytes is not None):
            return function(*args, **kwargs)
        return _inline_within(memory_bytes, function, *args, **kwargs)
    context = _get_context()
    reader, writer = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(writer, function, args, progress, memory_bytes, nice), daemon=True)
    try:
        process.start()
        writer.close()
        # A caller that stops waiting (a 504) kills the child at once, not at this thread's
        # next poll: the work stops with the answer, whatever this thread is waiting for.
        with deadline.on_cancel(process.kill):
            while True:
                if not reader.poll(POLL_S):  # true once a message is there, or the child is gone
                    deadline.check()
                    continue
                try:
                    kind, value = reader.recv()
                except EOFError:
                    process.join()
                    deadline.check()  # killed on cancel: the budget, not the worker, ended it
                    raise WorkerStopped(process.exitcode) from None
                if kind != "progress":
                    break
                deadline.progress(*value)
                deadline.check()
    finally:
        if process.is_alive():
            process.kill()
        if process.pid is not None:
            process.join()
        reader.close()
        writer.close()
    if kind == "error":
        raise value
    return value
