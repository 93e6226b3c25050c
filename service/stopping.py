"""A server process of ``toptraj serve`` ends within seconds of SIGTERM or SIGINT, whatever it is
doing, and takes every process it started with it.

uvicorn's signal handler only asks its server to stop (``Server.should_exit``), and the server
looks at that only once it serves: a process still importing or warming up (building robots,
loading the compiled kernels, the fork server importing the solver stacks) went on for tens of
seconds after SIGTERM, and a supervisor killed outright left its processes running with
parent 1. So each server process runs a watch (``watch``, started by its event loop factory
``serving.new_server_loop``, before uvicorn installs its handlers):

* A stop asked for while the process is starting (before ``serving()``, which the app's startup
  calls once it is done) ends it at once: every process descended from it is killed, then it
  exits.
* A stop asked for once it serves is uvicorn's graceful shutdown (open requests answered, the
  app's shutdown: running jobs marked interrupted, then ``stopped()`` kills the processes it
  started), cut after ``STOP_S`` seconds the same way.
* A server process spawned by uvicorn's supervisor gets SIGTERM from the kernel when the
  supervisor ends, even killed outright (Linux ``PR_SET_PDEATHSIG``).

The processes it started end with it: the fork server and its workers (``toptraj.planners.execution.isolated``,
which end with the fork server), the ``multiprocessing`` resource tracker.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import threading
import time

#: Seconds a serving process is given to shut down gracefully after a stop was asked for.
STOP_S = 3.0
#: Seconds between two looks at uvicorn's stop flag.
POLL_S = 0.05
#: uvicorn's own limit on the graceful shutdown (open requests), in s: before ``STOP_S``, so that
#: the app's shutdown runs.
GRACEFUL_S = 2

_serving = threading.Event()
_watching = False
_PR_SET_PDEATHSIG = 1


def serving() -> None:
    """Say that this process has started (its app's startup is done): a stop is graceful now."""
    _serving.set()


def stop_asked() -> bool:
    """True once uvicorn's signal handler of this process was called (its server's
    ``should_exit``; the handler is the server's bound ``handle_exit``)."""
    for signum in (signal.SIGTERM, signal.SIGINT):
        server = getattr(signal.getsignal(signum), "__self__", None)
        if getattr(server, "should_exit", False):
            return True
    return False


def descendants(pid: int) -> list[int]:
    """Process ids of every process descended from ``pid`` (children first), read from
    ``/proc`` (empty where there is none)."""
    parents: dict[int, int] = {}
    try:
        entries = os.listdir("/proc")
    except OSError:
        return []
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as handle:
                stat = handle.read()
        except OSError:  # gone meanwhile
            continue
        # "pid (comm) state ppid ...": comm may hold spaces and parentheses
        fields = stat[stat.rfind(b")") + 2 :].split()
        parents[int(entry)] = int(fields[1])
    found, frontier = [], [pid]
    while frontier:
        children = [child for child, parent in parents.items() if parent in frontier]
        found += children
        frontier = children
    return found


def _kill_descendants() -> None:
    for pid in descendants(os.getpid()):
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass


def end_now(status: int = 0) -> None:
    """Kill every process descended from this one, then exit at once (no cleanup: the
    interpreter would wait for the threads still computing)."""
    _kill_descendants()
    os._exit(status)


def stopped() -> None:
    """Say that the app of this process has shut down (its jobs' processes killed and marked):
    in a watched server process, kill the processes it started. The fork server would end by
    itself only once it has imported its solver stacks, seconds later."""
    if _watching:
        _kill_descendants()


def _end_with_supervisor() -> None:
    """Get SIGTERM when the process that spawned this one ends (Linux), as a stop."""
    parent = multiprocessing.parent_process()
    if parent is None:
        return
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):  # not Linux
        return
    if os.getppid() != parent.pid:  # it ended before the request: as if signalled
        os.kill(os.getpid(), signal.SIGTERM)


def _watch() -> None:
    while not stop_asked():
        time.sleep(POLL_S)
    if not _serving.is_set():
        end_now()
    time.sleep(STOP_S)
    end_now()


def watch() -> None:
    """Start the watch of this server process (once; from its main thread, before uvicorn
    installs its signal handlers)."""
    global _watching
    if _watching:
        return
    _watching = True
    _end_with_supervisor()
    threading.Thread(target=_watch, name="toptraj-stop-watch", daemon=True).start()
