"""The ``toptraj`` command: ``toptraj serve [--host H] [--port P] [--workers N] [--access-log]``, and
``toptraj plan|compare FILE|-`` (a trajectory, comparison or cell body) and ``toptraj plot FILE|- -o OUT.html`` (``toptraj.service.commands``)."""

from __future__ import annotations

import argparse
import atexit
import os
import sys

from toptraj.service import warmup

#: The app factory each server process calls (``create_app()``, settings from ``TOPTRAJ_*``).
APP_FACTORY = "toptraj.service.app:create_app"
#: Commands that answer one request and end (``run``).
ONE_SHOT = frozenset({"plan", "compare", "plot"})


def _commands():  # noqa: ANN202 - the module
    """``toptraj.service.commands``, imported when a command runs (``main`` first turns
    pydantic's plugins off for a one-shot command)."""
    from toptraj.service import commands

    return commands


def _batch_command():  # noqa: ANN202 - the module
    """``toptraj.service.batch_command``, imported when ``toptraj batch`` runs."""
    from toptraj.service import batch_command

    return batch_command


def plan_threads_per_process(workers: int, cores: int | None = None) -> int:
    """Planning threads of each of ``workers`` server processes sharing ``cores`` cores: the
    cores divided among the processes, at least 1. A process's planning threads share one
    interpreter lock, so they use one core at a time however many there are; the processes
    are what uses the cores."""
    cores = cores or os.cpu_count() or 1
    return max(1, cores // workers)


def port_in_use(host: str, port: int) -> bool:
    """Whether another process listens on ``host``:``port``: a trial bind, with the
    ``SO_REUSEADDR`` a server sets (so a port left in ``TIME_WAIT`` counts as free)."""
    import errno
    import socket

    try:
        family, kind, proto, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)[0]
    except OSError:
        return False  # an unknown host: the server's own start says so
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as error:
            return error.errno == errno.EADDRINUSE
    return False


def _serve(args) -> int:
    import uvicorn  # here, as the server's own modules: ``toptraj plan`` needs none of them

    from toptraj.service.serving import LOOP
    from toptraj.service.stopping import GRACEFUL_S

    if args.workers < 1:
        print(f"toptraj serve: --workers must be at least 1, not {args.workers}", file=sys.stderr)
        return 2
    if not 1 <= args.port <= 65535:  # uvicorn would take it modulo 65536 and say the port given
        print(f"toptraj serve: --port must be a port number from 1 to 65535, not {args.port}", file=sys.stderr)
        return 2
    refused = _settings_refused()
    if refused:  # said once here: each server process would refuse them and be started again, forever
        print(f"toptraj serve: {refused}", file=sys.stderr)
        return 2
    # Each server process reads its settings from the environment, which it inherits from here.
    os.environ.setdefault("TOPTRAJ_PLAN_WORKERS", str(plan_threads_per_process(args.workers)))
    # One process (workers=1) serves in this process; more are spawned processes sharing this
    # process's listening socket, each with its own app, planning threads and model caches,
    # restarted by uvicorn's supervisor if one dies, taking connections in turns (toptraj.service.serving).
    # A line per request costs the event loop about 0.2 ms of a 7 ms request (uvicorn's access
    # formatter and a write per line), so it is asked for, as gunicorn's is; errors are logged
    # either way.
    # A stop (SIGTERM, Ctrl-C) ends every process within seconds (toptraj.service.stopping): open
    # requests get GRACEFUL_S to finish.
    # Said before the seconds each process spends importing, and every few seconds while it
    # does (toptraj.service.warmup); each then logs its start-up steps. A single process imports the app
    # here, before uvicorn configures its logging; more import it in their own processes.
    if port_in_use(args.host, args.port):
        free = next((port for port in range(args.port + 1, min(args.port + 50, 65536)) if not port_in_use(args.host, port)), None)
        example = "" if free is None else f", e.g. --port {free} (free now)"
        print(f"toptraj serve: port {args.port} is in use (another server?): pass --port N{example}", file=sys.stderr)
        return 3
    print(f"toptraj serve: {args.workers} server process(es) on http://{args.host}:{args.port}", file=sys.stderr, flush=True)
    if args.workers == 1:
        process = os.getpid()
        warmup.say_while_importing(lambda line: print(f"INFO:     toptraj start-up [{process}]: {line}", file=sys.stderr, flush=True))
    uvicorn.run(
        APP_FACTORY,
        factory=True,
        host=args.host,
        port=args.port,
        workers=args.workers,
        loop=LOOP,
        access_log=args.access_log,
        timeout_graceful_shutdown=GRACEFUL_S,
    )
    return 0


def _settings_refused() -> str | None:
    """Why the ``TOPTRAJ_*`` settings of the environment cannot serve, or ``None``."""
    from pydantic import ValidationError

    from toptraj.service.settings import Settings

    try:
        Settings()
    except ValidationError as error:
        return "; ".join(
            (f"TOPTRAJ_{'_'.join(map(str, item['loc'])).upper()}: " if item["loc"] else "") + item["msg"].removeprefix("Value error, ")
            for item in error.errors()
        )
    return None


def _methods(text: str) -> list[str]:
    """``--methods a,b``: the names, spaces and empty items left out."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise argparse.ArgumentTypeError("give timing methods separated by commas, e.g. phase_plane,toppra")
    return names


def _request_commands(commands) -> None:
    """``toptraj plan``, ``toptraj compare`` and ``toptraj plot``: one request each."""
    exits = (
        "Exit status: 0 answered, 1 answered with an error (printed on stderr as problem+json), 2 the request could not "
        "be read or the answer not written, 130 interrupted (Ctrl-C)."
    )
    plan = commands.add_parser(
        "plan",
        help="plan one request and print the answer (errors on stderr)",
        description="Plan one request and print the answer, as POST /v1/trajectories (or, for a body naming methods, "
        "POST /v1/trajectories/compare; for a body naming arms, POST /v1/cells) would. " + exits,
    )
    plan.add_argument(
        "request", help="a JSON file shaped like the body of POST /v1/trajectories (or of a comparison, or of a cell), - for stdin"
    )
    plan.set_defaults(run=lambda args: _commands().plan(args.request))
    compare = commands.add_parser(
        "compare",
        help="time one path under several methods and print the comparison",
        description="Time one path under several methods: a table on a terminal (duration, ratio to the fastest, peak "
        "utilization, warnings), JSON when piped or with --json. " + exits,
    )
    compare.add_argument(
        "request",
        help="a JSON file shaped like the body of POST /v1/trajectories/compare, or of POST /v1/trajectories "
        "(its path and limits compared under --methods); - for stdin",
    )
    compare.add_argument(
        "--methods",
        type=_methods,
        default=None,
        help="timing methods, comma-separated, e.g. phase_plane,toppra (default: the request's own; for a trajectory "
        "request, its method then phase_plane, toppra and quintic, or on a free path collocation and search)",
    )
    compare.add_argument("--json", action="store_true", help="print JSON even on a terminal")
    compare.set_defaults(run=lambda args: _commands().compare(args.request, args.methods, True if args.json else None))
    plot = commands.add_parser(
        "plot",
        help="write the web page's plots of one request to a self-contained HTML file",
        description="Write the plots of one request to a self-contained HTML file (it opens offline): the phase plane, "
        "the joints against their limits and the arm; for a comparison, every method drawn over the others; for a cell, "
        "its coordination diagram, each arm's joints and the arms together. " + exits,
    )
    plot.add_argument("request", help="a JSON file shaped like the body of POST /v1/trajectories, of a comparison or of a cell; - for stdin")
    plot.add_argument("-o", "--output", required=True, help="the HTML file to write")
    plot.add_argument("--methods", type=_methods, default=None, help="compare these timing methods, comma-separated, e.g. phase_plane,toppra")
    plot.set_defaults(run=lambda args: _commands().plot(args.request, args.output, args.methods))


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script."""
    parser = argparse.ArgumentParser(
        prog="toptraj",
        description="Time-optimal trajectories for robot arms: serve the HTTP service, or plan, compare and\n"
        "plot requests (JSON files shaped like the service's request bodies) in this process.",
        epilog="examples:\n"
        "  toptraj serve --port 8000\n"
        "  toptraj plan examples/ur5_spline.json > answer.json\n"
        "  toptraj compare examples/ur5_spline.json --methods phase_plane,toppra,quintic\n"
        "  toptraj plot examples/compare_methods.json -o compare.html\n\n"
        "toptraj COMMAND --help describes each command.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    serve = commands.add_parser("serve", help="run the HTTP service", description="Run the HTTP service (the API, its documentation at /docs and the web page at /).")
    serve.add_argument("--host", default="127.0.0.1", help="the address to listen on (default: 127.0.0.1; 0.0.0.0 for every interface)")
    serve.add_argument("--port", type=int, default=8000, help="the port to listen on (default: 8000)")
    serve.add_argument(
        "--workers",
        type=int,
        default=os.cpu_count() or 1,
        help="server processes on the port, each planning on its own core (default: the number of cores)",
    )
    serve.add_argument("--access-log", action="store_true", help="log a line per request (uvicorn's access log; default off)")
    serve.set_defaults(run=_serve)
    _request_commands(commands)
    batch = commands.add_parser(
        "batch",
        help="plan a file of requests (JSON Lines) on Ray, resumably",
        description="Plan a file of requests, one POST /v1/trajectories (or compare) body per line, on Ray: a result line "
        "per request line in the output as each finishes (its line number, status and body); run again, it plans only "
        "the lines without a result. Exit status: 0 every line answered (a line's error is its result), 2 the files or "
        "options cannot be used, 130 interrupted (the command that resumes is printed).",
    )
    batch.add_argument("requests", help="a JSON Lines file: a POST /v1/trajectories (or compare) body per line")
    batch.add_argument("-o", "--output", required=True, help="the JSON Lines file of results (appended; resumed)")
    batch.add_argument("--workers", type=int, default=None, help="Ray workers (CPUs) of a local Ray (default: the cores)")
    batch.add_argument("--ray-address", default=None, help="an existing Ray cluster: host:port of its head, auto or ray://host:port (default: a local Ray)")
    batch.add_argument("--budget", type=float, default=None, help="planning budget of each request, in s (default: 20; a line over it is a 504)")
    batch.add_argument(
        "--retry-failed", action="store_true", help="plan again the lines answered with a budget error (504) or another 5xx"
    )
    batch.set_defaults(
        run=lambda args: _batch_command().batch(args.requests, args.output, args.workers, args.ray_address, args.budget, args.retry_failed)
    )
    args = parser.parse_args(argv)
    if args.command in ONE_SHOT:
        # pydantic's plugins (unless asked for): finding them scans every installed package's
        # entry points, about 30 ms of toptraj plan's start; the service's models are made after this
        os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")
        # the kernels the install compiled ahead of time, without numba's start (toptraj.compiled)
        os.environ.setdefault("TOPTRAJ_KERNELS", "library")
        try:
            return args.run(args)
        except KeyboardInterrupt:  # Ctrl-C: the status a shell gives an interrupted command, no traceback
            print(f"toptraj {args.command}: interrupted", file=sys.stderr)
            return 130
    return args.run(args)


def run() -> None:
    """The ``toptraj`` program: ``main``; after a command of ``ONE_SHOT`` the process ends as
    soon as its output is flushed and its exit handlers have run, without the interpreter's
    teardown of every module, which after numba's compiled kernels were loaded takes about
    0.3 s of CPU: a quarter of ``toptraj plan``'s (``benchmarks/startup.py``). Such a command
    keeps no thread, child process or open file of its own at that point. Tests call ``main``."""
    status = main()
    if sys.argv[1:2] and sys.argv[1] in ONE_SHOT:
        for stream in (sys.stdout, sys.stderr):
            try:
                if stream is not None:  # None: closed when the command started (>&-)
                    stream.flush()
            except (OSError, ValueError):  # a reader gone (| head) or a stream closed
                pass
        atexit._run_exitfuncs()  # logging's flush, pending finalizers, llvmlite's and numba's flags
        os._exit(status)
    sys.exit(status)


if __name__ == "__main__":
    run()
