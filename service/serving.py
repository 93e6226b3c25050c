"""How ``toptraj serve --workers N`` spreads connections over N server processes on one port.

uvicorn's multi-process mode binds the port once and spawns N processes that each run the app
(``toptraj.service.app:create_app``) and accept connections from the one listening socket. A process
plans on one core at a time (its planning threads share one interpreter lock), so the processes
are what uses the cores, and a keep-alive connection stays with the process that accepted it:
how connections spread over the processes decides how many cores a few clients can use.

An event loop's own accept loop takes every connection waiting on the socket at once, and the
process that is running when a burst of connections arrives (four clients opening theirs
together) takes them all before a sleeping one is scheduled: measured on a loaded 2-core
machine, four simultaneous connections all landed on one of two processes in 14 of 30 bursts
with uvloop's loop, 19 of 30 with asyncio's, and sixteen in 5 to 10 of 30.

``new_event_loop`` (through uvicorn's ``loop`` setting, ``LOOP``) makes the event loop of each server
process, a ``BalancedEventLoop``: uvloop's when it is installed, else asyncio's. Its servers on a given listening socket (the one
uvicorn shares among its processes) take one connection per turn, and a process that already
holds ``k`` open connections lets a waiting connection wait ``min(k, MAX_TURNS) x TURN_S``
before taking it, so that a process holding fewer (an idle one first, which takes it at once)
gets it: in 60 such bursts of four, none landed on one process. The processes share nothing but the
socket; a process that is alone, or whose peers are slower still, takes the connection after
its wait. A new connection to a process holding others thus waits at most ``MAX_TURNS x TURN_S``
(4 ms) to be accepted, once per connection: a keep-alive client pays it once.

The event loop shares its process's interpreter lock with the planning threads, which hold it
between the interpreter's forced switches; ``new_event_loop`` shortens the switch interval from
5 ms to ``SWITCH_INTERVAL_S`` (1 ms), so that the event loop, which needs the lock a few times
per request (accept, read, answer), gets it back sooner: on ``/health`` during a 16-client load
this took the p50 from 18.5 to 13.8 ms (medians of three interleaved rounds on a loaded 2-core
machine), at no measured cost to the plannings.
"""

from __future__ import annotations

import asyncio
import errno
import logging
import os
import socket
import sys
import weakref
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    _BaseLoop = asyncio.SelectorEventLoop
else:
    try:
        from uvloop import Loop as _BaseLoop
    except ImportError:  # pragma: no cover - uvloop is a dependency where it builds
        _BaseLoop = asyncio.SelectorEventLoop

#: uvicorn's ``loop`` setting naming the event loop class of each server process.
LOOP = "toptraj.service.serving:new_server_loop"
#: The interpreter's thread switch interval in a server process, in s (Python's default: 5 ms).
SWITCH_INTERVAL_S = 0.001
#: Wait per open connection before a process takes the next one, in s.
TURN_S = 0.001
#: Open connections beyond which the wait grows no longer.
MAX_TURNS = 4
#: Pause after an accept failed for want of resources (too many open files), in s.
RETRY_S = 1.0

_log = logging.getLogger("uvicorn.error")
_RESOURCE_ERRORS = {errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM}
#: The connection sockets the balanced servers of this process accepted: what its turn at
#: accepting waits on, and what a planning asks before a try on the event loop.
_accepted: weakref.WeakSet[socket.socket] = weakref.WeakSet()


def open_connections() -> int:
    """How many connections the balanced servers of this process hold open (0 when it serves
    none: a test client, or uvicorn's own loop)."""
    return sum(1 for connection in list(_accepted) if connection.fileno() != -1)


class BalancedEventLoop(_BaseLoop):
    """The default event loop, except that a server on a given plain TCP listening socket (the
    one uvicorn shares among its processes) accepts in turns, as the module says. A server it
    creates from a host and port (one process), or with TLS, accepts as the loop does."""

    async def create_server(self, protocol_factory, *args, sock: socket.socket | None = None, **kwargs):
        if sock is None or sock.type != socket.SOCK_STREAM or kwargs.get("ssl") is not None:
            return await super().create_server(protocol_factory, *args, sock=sock, **kwargs)
        return _ServerInTurns(self, sock, protocol_factory, kwargs.get("backlog", 100))


def new_server_loop() -> asyncio.AbstractEventLoop:
    """The event loop of a ``toptraj serve`` process (uvicorn's ``loop`` setting, ``LOOP``):
    ``new_event_loop``'s, once the process's stop watch runs (``toptraj.service.stopping``; uvicorn
    makes the loop before it installs its signal handlers and before it loads the app) and
    while it says, every few seconds, that it is importing the app (``toptraj.service.warmup``)."""
    from toptraj.service import stopping, warmup

    stopping.watch()
    if "toptraj.service.app" not in sys.modules:  # one process: uvicorn imported it before (toptraj serve says so)
        process = os.getpid()
        warmup.say_while_importing(lambda line: _log.info("toptraj start-up [%d]: %s", process, line))
    return new_event_loop()


def new_event_loop() -> asyncio.AbstractEventLoop:
    """The event loop of a server process; sets the process's thread switch interval to
    ``SWITCH_INTERVAL_S``."""
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    return BalancedEventLoop()


class _ServerInTurns:
    """What uvicorn uses of a server (``close``, ``wait_closed``), serving ``listening`` by
    ``_accept_in_turns``."""

    def __init__(self, loop: asyncio.AbstractEventLoop, listening: socket.socket, protocol_factory, backlog: int):
        self._loop, self._listening, self._fd = loop, listening, listening.fileno()
        listening.setblocking(False)
        listening.listen(backlog)
        self._task = loop.create_task(_accept_in_turns(loop, listening, protocol_factory))

    @property
    def sockets(self) -> tuple[socket.socket, ...]:
        return () if self._listening.fileno() == -1 else (self._listening,)

    def is_serving(self) -> bool:
        return not self._task.done()

    def close(self) -> None:
        """Stop accepting (connections already accepted stay open) and close the socket."""
        if self._listening.fileno() == -1:
            return
        self._task.cancel()
        self._loop.remove_reader(self._fd)
        self._listening.close()

    async def wait_closed(self) -> None:
        try:
            await self._task
        except asyncio.CancelledError:
            pass


async def _wait_readable(loop: asyncio.AbstractEventLoop, sock: socket.socket) -> None:
    """Return once ``sock`` is readable (for a listening socket: a connection waits)."""
    readable = loop.create_future()
    fd = sock.fileno()
    def ready() -> None:
        if not readable.done():
            readable.set_result(None)

    loop.add_reader(fd, ready)
    try:
        await readable
    finally:
        if sock.fileno() == fd:  # once closed, the number may belong to another socket
            loop.remove_reader(fd)


async def _accept_in_turns(loop: asyncio.AbstractEventLoop, listening: socket.socket, protocol_factory) -> None:
    """Accept connections on ``listening`` one per turn until it is closed."""
    while listening.fileno() != -1:
        await _wait_readable(loop, listening)
        held = open_connections()
        if held:
            await asyncio.sleep(min(held, MAX_TURNS) * TURN_S)
        try:
            connection, _ = listening.accept()
        except (BlockingIOError, InterruptedError, ConnectionAbortedError):
            continue  # another process took it
        except OSError as error:
            if error.errno not in _RESOURCE_ERRORS:
                raise
            _log.error("cannot accept a connection (%s); retrying in %g s", error, RETRY_S)
            await asyncio.sleep(RETRY_S)
            continue
        connection.setblocking(False)
        _accepted.add(connection)
        try:
            await loop.connect_accepted_socket(protocol_factory, connection)
        except (OSError, ValueError) as error:  # the peer went away before it was served
            _log.debug("accepted connection dropped: %s", error)
            connection.close()
