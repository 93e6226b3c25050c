"""Ray as the batch driver's pool (``runner``): a local Ray started here or a cluster at an
address, tasks of request chunks (``work.answer_on_worker``), each worker prepared once; and the
address of a cluster tried before Ray is asked to join it."""

from __future__ import annotations

import os
from collections import Counter
from typing import Any

from toptraj.robots.errors import ToptrajError

#: What ``toptraj batch`` needs and how to get it.
RAY_MISSING = "toptraj batch plans on Ray, which is not installed: pip install 'toptraj[ray]'"


class RayMissing(RuntimeError):
    """Ray (the ``ray`` extra) is not installed."""


class RayClientMissing(RayMissing):
    """Ray is installed, but not the packages Ray Client (``ray://``) needs."""


class RayUnreachable(ToptrajError):
    """No Ray cluster answers at the address given (503: the server's ``TOPTRAJ_RAY_ADDRESS``
    for a batch job; ``toptraj batch`` says it as its own problem)."""

    status = 503
    title = "Ray cluster unreachable"


#: Seconds a cluster's address is given to accept a connection before the batch starts.
CONNECT_S = 5.0


def check_reachable(address: str, option: str = "--ray-address") -> None:
    """Refuse at once a ``host:port`` (or ``ray://host:port``) where nothing accepts a
    connection: Ray itself retries such an address for minutes, deaf to Ctrl-C. ``option``
    names where the address was given (the CLI's option, or the server's setting).

    Raises:
        RayUnreachable: nothing listens there (within ``CONNECT_S``), or a server that is no
            Ray head (``_answers_http2``), with how to start one.
    """
    import socket

    host, _, port = address.removeprefix("ray://").rpartition(":")
    host = host.strip("[]")  # an IPv6 address in brackets
    if not host or not port.isdigit():
        raise RayUnreachable(
            f"{option} {address!r} is no cluster address: give host:port of its head (as `ray start --head` "
            "prints it), ray://host:port for a Ray client server, auto for the cluster started on this machine, or "
            f"{_local(option)}"
        )
    try:
        with socket.create_connection((host, int(port)), timeout=CONNECT_S) as connection:
            speaks_grpc = _answers_http2(connection)
    except OSError as error:
        raise RayUnreachable(
            f"nothing accepts a connection at {option} {address} ({error.strerror or error}): start the cluster's "
            f"head there (ray start --head --port={port}), check the address it printed, or {_local(option)}"
        ) from None
    if not speaks_grpc:
        raise RayUnreachable(
            f"{option} {address} is no Ray cluster: a server answers there, but not as Ray's head does (gRPC); "
            "give the address `ray start --head` printed (its GCS port, 6379 by default), ray://host:10001 for "
            f"a Ray client server, or {_local(option)}"
        )


#: The client's opening of an HTTP/2 connection (RFC 9113, section 3.4): the preface and an
#: empty SETTINGS frame. A gRPC server (a Ray head's GCS, a Ray client server) answers with its
#: own SETTINGS frame (type 0x4); another server (HTTP/1, SSH, a database) with something else,
#: or nothing until it closes.
_HTTP2_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes([0, 0, 0, 4, 0, 0, 0, 0, 0])


def _answers_http2(connection) -> bool:
    """Whether the server on ``connection`` opens HTTP/2 as a gRPC server does, within
    ``CONNECT_S``; ``True`` under ``RAY_USE_TLS`` (its gRPC is then behind TLS, which this
    plain probe cannot open). Ray itself would retry any other server for minutes."""
    if os.environ.get("RAY_USE_TLS", "0").lower() in ("1", "true"):
        return True
    head = b""
    try:
        connection.sendall(_HTTP2_PREFACE)
        while len(head) < 9:
            chunk = connection.recv(9 - len(head))
            if not chunk:
                break
            head += chunk
    except OSError:  # a timeout, or a server that resets the connection: it accepted one, so not "nothing listens"
        return False
    return len(head) == 9 and head[3] == 4



def _local(option: str) -> str:
    """How to plan on a local Ray instead, where the address was given as ``option``."""
    return "leave --ray-address out for a local Ray" if option.startswith("--") else f"set {option}=local for a Ray of the job's own"


class RayPool:
    """Chunks of requests computed as Ray tasks (``work.answer_on_worker``): on the cluster at
    ``address`` (``auto``, ``host:port``, ``ray://host:port``), or on a local Ray with
    ``workers`` CPUs (default: the cores) started here and shut down by ``close`` with its
    processes. Each worker is prepared once (``prepare``: Ray's worker setup hook, in this
    job's ``runtime_env``); tasks are spread over the nodes (``SPREAD``); ``nodes`` counts the
    requests answered by each node (by Ray node id).

    Raises:
        RayMissing: Ray is not installed.
    """

    def __init__(self, address: str | None = None, workers: int | None = None):
        try:
            import ray
        except ImportError:
            raise RayMissing(RAY_MISSING) from None
        from toptraj.service.batches.prepare import SETUP_HOOK
        from toptraj.service.batches.work import answer_on_worker

        self._ray = ray
        self._started_here = False
        if address is None and os.environ.get("RAY_ADDRESS"):  # Ray's own variable names the cluster
            address = os.environ["RAY_ADDRESS"]
        self.nodes: Counter[str] = Counter()
        if not ray.is_initialized():
            hook = {"worker_process_setup_hook": SETUP_HOOK}
            if address in (None, "local"):
                cpus = workers or os.cpu_count() or 1
                ray.init(
                    address="local",  # a Ray of its own, not a cluster started on this machine
                    num_cpus=cpus,
                    include_dashboard=False,
                    object_store_memory=100 * 1024 * 1024,
                    log_to_driver=False,
                    configure_logging=False,
                    runtime_env=hook,
                )
            else:
                if address != "auto":
                    check_reachable(address)
                try:
                    ray.init(address=address, log_to_driver=False, configure_logging=False, runtime_env=hook)
                except ValueError as error:  # ray://: Ray Client needs packages of its own
                    if "ray[client]" not in str(error):
                        raise
                    raise RayClientMissing(
                        f"--ray-address {address} connects through Ray Client, which needs Ray's client packages "
                        "(pip install 'ray[client]'); or give the head's host:port (the address `ray start --head` "
                        "printed) to connect without it"
                    ) from None
                except ConnectionError as error:  # no cluster there ("auto": none on this machine)
                    where = "runs on this machine" if address == "auto" else "answers"
                    raise RayUnreachable(
                        f"no Ray cluster {where} for --ray-address {address} ({str(error)[:200]}): start "
                        "one (ray start --head), give a cluster's head as --ray-address host:port, or leave "
                        "--ray-address out for a local Ray"
                    ) from None
            self._started_here = True
        self._remote = ray.remote(num_cpus=1, max_retries=2, scheduling_strategy="SPREAD")(answer_on_worker)
        self._uploads: Any = ray.put({})
        self.cpus = int(ray.available_resources().get("CPU", workers or 1) or 1)

    def share(self, uploads: dict[str, tuple[str, str]]) -> None:
        """The uploaded robots (``_uploads_named``) every later task receives."""
        self._uploads = self._ray.put(uploads)

    def submit(self, chunk: list[tuple[str, str]], budget_s: float) -> Any:
        """Start computing ``chunk`` of (key, text); a handle for ``wait`` and ``result``."""
        return self._remote.remote(chunk, self._uploads, budget_s, None)  # no body cap: a file's lines

    def wait(self, handles: list, timeout_s: float) -> tuple[list, list]:
        """(finished, still running) of ``handles``, once one finished or after ``timeout_s``."""
        ready, rest = self._ray.wait(handles, num_returns=1, timeout=timeout_s)
        if ready and rest:
            more, rest = self._ray.wait(rest, num_returns=len(rest), timeout=0)
            ready += more
        return ready, rest

    def result(self, handle: Any) -> list[tuple[str, int, bytes]]:
        """(key, status, body) of each request of a finished task (raises its failure)."""
        node, answers = self._ray.get(handle)
        self.nodes[node] += len(answers)
        return answers

    def cancel(self, handles: list) -> None:
        """Stop these tasks, killing the workers that run them."""
        for handle in handles:
            self._ray.cancel(handle, force=True)

    def close(self) -> None:
        """Shut down a Ray started here (its processes with it)."""
        if self._started_here:
            self._ray.shutdown()
