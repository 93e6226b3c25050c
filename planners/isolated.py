"""Computations that cannot check a deadline themselves (a convex solver, an SQP step) run in a
child process that is killed when the deadline passes.

``run_isolated(function, *args, deadline=...)`` starts a child process, calls
``function(*args)`` there and returns its result; the calling thread waits on a pipe and checks
``deadline`` every ``POLL_S`` seconds, and once the deadline passes (or is cancelled) the child is
killed and ``BudgetExceeded`` raised. The function must be a module-level function and its
arguments and result plain picklable data (numpy arrays, dataclasses of them, a ``Robot``), never
closures. The memory the child used goes back to the system when it exits. Without a deadline
(``NO_DEADLINE``, the library's default) the function runs in the calling thread: there is
nothing to stop it for.

Children are forked from a fork server (``multiprocessing``'s ``forkserver`` context): a clean,
single-threaded process started once, which has imported the solver stacks (``PRELOAD``), so a
child starts in milliseconds without copying the threads of the server. Where ``forkserver`` is
not available, children are spawned (a fresh interpreter each). A child keeps to one BLAS
thread (``planners.threads``). As with any ``multiprocessing``
code, a script that plans with a deadline must guard its entry point with
``if __name__ == "__main__":`` (a child imports the main script as ``__mp_main__``).
"""

from __future__ import annotations

import multiprocessing
import threading

from planners.deadline import NO_DEADLINE, Deadline
from planners.errors import TimingFailed
from planners.threads import single_blas_thread

#: Seconds between two deadline checks while waiting for the child.
POLL_S = 0.02
#: Modules the fork server imports once, so that children start with them loaded.
PRELOAD = ["numpy", "scipy.optimize", "cvxpy", "clarabel", "pinocchio", "planners.timing.min_cost", "planners.free_path.collocation"]

_context = None
_lock = threading.Lock()


def _get_context():
    global _context
    with _lock:
        if _context is None:
            if "forkserver" in multiprocessing.get_all_start_methods():
                context = multiprocessing.get_context("forkserver")
                context.set_forkserver_preload(PRELOAD)
            else:
                context = multiprocessing.get_context("spawn")
            _context = context
        return _context


def start_worker_server() -> None:
    """Start the fork server now, so that it imports ``PRELOAD`` (a second or two, in its own
    process) while the service starts, rather than during the first isolated call."""
    context = _get_context()
    if context.get_start_method() == "forkserver":
        from multiprocessing import forkserver

        forkserver.ensure_running()


def _child(connection, function, args) -> None:
    single_blas_thread()
    try:
        outcome = ("result", function(*args))
    except Exception as error:  # returned to the parent, which raises it
        outcome = ("error", error)
    try:
        connection.send(outcome)
    except Exception as error:  # an unpicklable result or error
        connection.send(("error", TimingFailed(f"the worker process could not return its answer: {error!r}")))
    finally:
        connection.close()


def run_isolated(function, *args, deadline: Deadline = NO_DEADLINE):
    """``function(*args)`` computed in a child process, killed once ``deadline`` passes.

    Raises:
        BudgetExceeded: the deadline passed or was cancelled (the child is killed first).
        TimingFailed: the child died without an answer (e.g. killed by the system for memory).
        Whatever ``function`` raised, re-raised here.
    """
    if deadline is NO_DEADLINE:
        return function(*args)
    context = _get_context()
    reader, writer = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(writer, function, args), daemon=True)
    try:
        process.start()
        writer.close()
        while not reader.poll(POLL_S):  # true once the answer is there, or the child is gone
            deadline.check()
        try:
            kind, value = reader.recv()
        except EOFError:
            process.join()
            raise TimingFailed(f"the worker process stopped without an answer (exit code {process.exitcode})") from None
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
