"""What ``toptraj plan``, ``toptraj compare`` and ``toptraj plot`` do: one request read from a
file or standard input (``-``), planned in this process by the service's own code path
(``toptraj.service.planning``), its answer on standard output (a comparison as a table on a terminal,
``toptraj.service.compare_table``; or a page of plots in a file), its error as problem+json on standard
error with a non-zero exit status:

* 0: answered;
* 1: the request was answered with an error (422 malformed or impossible, 404 unknown robot, …);
* 2: the request could not be read (no such file, not JSON).

Writing into a closed pipe (``toptraj plan r.json | head``) ends quietly.
"""

from __future__ import annotations

import io
import json
import os
import sys
from collections.abc import Callable

from pydantic import ValidationError

from toptraj.service.body_limit import DEFAULT_MAX_BODY_BYTES


class _Unreadable(Exception):
    """The request cannot be read: exit status 2."""


def _plain(value: object) -> object:
    """A numpy scalar among an error's facts as the Python number JSON writes."""
    return value.item() if hasattr(value, "item") else str(value)


def _problem(title: str, status: int, detail: str) -> dict:
    return {"type": "about:blank", "title": title, "status": status, "detail": detail}


#: Largest request read (bytes): the server's default body cap, checked before the request is
#: read whole.
MAX_REQUEST_BYTES = DEFAULT_MAX_BODY_BYTES


def _read(source: str) -> str:
    """The request at ``source`` (a file, or ``-`` for standard input), at most
    ``MAX_REQUEST_BYTES`` read, a byte order mark ignored as over HTTP."""
    try:
        if source == "-":
            if sys.stdin is None:
                raise _Unreadable("cannot read the request from standard input: it is closed")
            binary = getattr(sys.stdin, "buffer", None)  # a text stream without one (a test's) is read as text
            raw = binary.read(MAX_REQUEST_BYTES + 1) if binary is not None else sys.stdin.read(MAX_REQUEST_BYTES + 1).encode()
        else:
            with open(source, "rb") as handle:
                raw = handle.read(MAX_REQUEST_BYTES + 1)
        if len(raw) > MAX_REQUEST_BYTES:
            raise _Unreadable(
                f"the request {source!r} holds more than {MAX_REQUEST_BYTES:,} bytes, the most a request holds (as the "
                "server's body cap): is it a request? A path of many points is better given by fewer waypoints"
            )
        return raw.decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        raise _Unreadable(f"cannot read the request {source!r}: {error}") from None


def _json(text: str):
    try:
        return json.loads(text)
    except ValueError:
        raise _Unreadable("the request is not JSON") from None


def _unique_keys(source: str, text: str) -> str:
    """``text``, once it nests no deeper than a request may and is JSON (``_Unreadable`` saying
    how deep, or where it goes wrong, otherwise) and no object of it gives a key twice
    (``DuplicateKey`` otherwise)."""
    from toptraj.service.strict_json import EMPTY_BODY, DuplicateKey, NumberTooLong, decode_error, loads, refused_depth, too_deep

    if not text.strip():
        raise _Unreadable(f"{source}: {EMPTY_BODY}".replace("the body is", "the request is"))
    depth = refused_depth(text.encode())
    if depth is not None:
        raise _Unreadable(f"{source}: the request {too_deep(depth)}")
    try:
        loads(text)
    except DuplicateKey:
        raise
    except json.JSONDecodeError as error:
        raise _Unreadable(f"{source}: {decode_error(error)}") from None
    except NumberTooLong as error:
        raise _Unreadable(f"{source}: {error}") from None
    except (ValueError, RecursionError):
        pass
    return text


def _is_cell(text: str) -> bool:
    """A cell body (``POST /v1/cells``) names its ``arms``."""
    body = _json(text)
    return isinstance(body, dict) and "arms" in body


def _no_cell(text: str, why: str) -> str:
    """``text``, unless it is a cell body: then InvalidRequest saying ``why`` and what a cell takes."""
    if _is_cell(text):
        from toptraj.planners.errors import InvalidRequest

        raise InvalidRequest("arms", detail=f"{why}; a cell (a body with arms) is planned by toptraj plan and drawn by toptraj plot (without --methods)")
    return text


def _is_compare(text: str) -> bool:
    """A compare body names its ``methods``."""
    body = _json(text)
    return isinstance(body, dict) and "methods" in body


#: Methods ``toptraj compare`` runs on a trajectory body given without ``--methods``, after
#: the body's own ``timing.method``; on a free path (start and goal only), ``FREE_METHODS``.
DEFAULT_METHODS = ("phase_plane", "toppra", "quintic")
FREE_METHODS = ("collocation", "search")


def compare_body(text: str, methods: list[str] | None = None, left_out: list[str] | None = None) -> str:
    """The compare body (JSON) of ``text``: a compare body, its ``methods`` replaced by
    ``methods`` when given; or a trajectory body's robot, path and timing (its ``output`` left
    out) under ``methods``, by default its own method then those of ``DEFAULT_METHODS``
    (``FREE_METHODS`` on a free path) that serve its timing as it is (a jerk limit, a cost: each
    one left out is added to ``left_out`` with why); its ``timing.method`` is taken out, the
    methods saying what runs."""
    body = _json(text)
    if not isinstance(body, dict):
        return text  # refused by the schema, which says what it expects
    if "methods" in body:
        return text if methods is None else json.dumps({**body, "methods": methods})
    timing = body.get("timing")
    own = timing.get("method", "phase_plane") if isinstance(timing, dict) else "phase_plane"
    path = body.get("path")
    defaults = FREE_METHODS if isinstance(path, dict) and path.get("kind") == "free" else DEFAULT_METHODS
    chosen = methods or list(dict.fromkeys([own, *defaults] if isinstance(own, str) else defaults))
    shared = {key: value for key, value in body.items() if key != "output"}
    if isinstance(timing, dict):
        shared["timing"] = {key: value for key, value in timing.items() if key != "method"}
    if methods is None and isinstance(own, str):
        chosen = [name for name in chosen if name == own or _serves(shared, name, left_out)]
    return json.dumps({**shared, "methods": chosen})


def _serves(body: dict, method: str, left_out: list[str] | None) -> bool:
    """Whether ``method`` serves the trajectory ``body``'s timing as it is (a problem of it can
    be built; anything but a setting the method does not serve counts as served, for the
    comparison to report); when not, why, added to ``left_out``."""
    from toptraj.planners.errors import NotServed
    from toptraj.planners.execution.deadline import NO_DEADLINE
    from toptraj.planners.execution.memory import DEFAULT_SEARCH_MEMORY, MAX_SAMPLES
    from toptraj.service.equipping import equipped_robot
    from toptraj.service.mapping import problem_of
    from toptraj.service.problems import request_field
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    try:
        request = TrajectoryRequest.model_validate({**body, "timing": {**body.get("timing", {}), "method": method}})
        problem_of(request, equipped_robot(request), NO_DEADLINE, MAX_SAMPLES, False, DEFAULT_SEARCH_MEMORY)
    except NotServed as error:
        if left_out is not None:
            value = f" {error.value!r}" if isinstance(error.value, str) else ""
            left_out.append(f"{method} (it does not serve {request_field(error.field)}{value})")
        return False
    except Exception:  # noqa: BLE001 - any other failure is the comparison's to report
        return True
    return True


def _run(source: str, answer: Callable[[str], bytes], out=None) -> int:
    """Read the request at ``source``, compute ``answer(text)`` and write it to ``out``
    (standard output); errors to standard error as problem+json."""
    from toptraj.robots import ToptrajError
    from toptraj.service.problems import detail, problem_facts, status_of, title_of, validation_problem
    from toptraj.service.strict_json import DuplicateKey

    try:
        content = answer(_unique_keys(source, _read(source)))
    except DuplicateKey as error:
        print(json.dumps(error.problem()), file=sys.stderr)
        return 1
    except _Unreadable as error:
        print(json.dumps(_problem("Cannot read request", 400, str(error))), file=sys.stderr)
        return 2
    except ValidationError as error:
        print(json.dumps(validation_problem(error, _schema_named(error.title))), file=sys.stderr)
        return 1
    except ToptrajError as error:
        print(json.dumps({**_problem(title_of(error), status_of(error), detail(error)), **problem_facts(error)}, default=_plain), file=sys.stderr)
        return 1
    return _write(content, out)


def _schema_named(title: str) -> type | None:
    """The request schema a ``ValidationError`` of that title is about (for its hints)."""
    from toptraj.service.schemas.cells import CellRequest
    from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest

    return {schema.__name__: schema for schema in (TrajectoryRequest, CompareRequest, CellRequest)}.get(title)


def _write(content: bytes, out=None) -> int:
    if out is None and sys.stdout is None:
        print(json.dumps(_problem("Cannot write the answer", 400, "standard output is closed: redirect it to a file")), file=sys.stderr)
        return 2
    stream = out or sys.stdout.buffer
    try:
        stream.write(content if content.endswith(b"\n") else content + b"\n")
        stream.flush()
    except BrokenPipeError:
        # The reader has gone (``| head``): say nothing more; stdout points at /dev/null so that
        # the interpreter's own flush at exit stays quiet too.
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, io.UnsupportedOperation):  # stdout is no file (a test's capture)
            pass
    except OSError as error:  # a full disk, a closed descriptor
        print(json.dumps(_problem("Cannot write the answer", 400, f"standard output: {error}")), file=sys.stderr)
        return 2
    return 0


def _trajectory(text: str) -> bytes:
    from toptraj.service.planning import plan_request, render
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    request = TrajectoryRequest.model_validate_json(text)
    return render(plan_request(request), request)[0]


def _compare(text: str, as_table: bool = False, outcome: dict | None = None) -> bytes:
    """The comparison of the compare body ``text``, as a table or JSON; ``outcome["failed"]``
    set to whether every method failed."""
    from toptraj.planners.execution.deadline import NO_DEADLINE
    from toptraj.service.planning import compare_request, encode_json
    from toptraj.service.schemas.trajectories import CompareRequest

    answer = compare_request(CompareRequest.model_validate_json(text), NO_DEADLINE)
    if outcome is not None:
        outcome["failed"] = all("error" in result for result in answer["results"])
    if as_table:
        from toptraj.service.compare_table import compare_table

        return compare_table(answer).encode()
    return encode_json(answer)


def _cell(text: str, page: bool = False) -> bytes:
    """A cell body's answer, as ``POST /v1/cells`` gives it (its ``format``; CSV included), or
    with ``page`` its plots (``toptraj.service.cell_plots``)."""
    from toptraj.planners.execution.deadline import NO_DEADLINE
    from toptraj.service.cell_answers import csv_bytes
    from toptraj.service.cells import plan_cell
    from toptraj.service.planning import encode_json
    from toptraj.service.schemas.cells import CellRequest

    request = CellRequest.model_validate_json(text)
    if page:
        from toptraj.service.cell_plots import cell_html

        return cell_html(plan_cell(request, NO_DEADLINE, "samples")).encode()
    if request.format == "csv":
        return csv_bytes(plan_cell(request, NO_DEADLINE, "csv"))
    return encode_json(plan_cell(request, NO_DEADLINE))


def plan(source: str) -> int:
    """``toptraj plan FILE|-``: a trajectory body, a compare body (it names ``methods``) or a
    cell body (it names ``arms``)."""

    def answer(text: str) -> bytes:
        if _is_cell(text):
            return _cell(text)
        return _compare(text) if _is_compare(text) else _trajectory(text)

    return _run(source, answer)


def compare(source: str, methods: list[str] | None = None, as_json: bool | None = None) -> int:
    """``toptraj compare FILE|- [--methods a,b] [--json]``: a compare body, or a trajectory body
    compared under ``methods`` (``compare_body``); a table on a terminal, JSON when piped or
    when ``as_json``. Exit status 1 when every method failed (their errors are in the answer)."""
    as_table = (sys.stdout is not None and sys.stdout.isatty()) if as_json is None else not as_json
    why = "toptraj compare times one arm's path under several methods"
    left_out: list[str] = []
    outcome: dict = {}

    def answer(text: str) -> bytes:
        body = compare_body(_no_cell(text, why), methods, left_out)
        if left_out:
            print(f"toptraj compare: left out {'; '.join(left_out)}; --methods names the methods to run", file=sys.stderr)
        return _compare(body, as_table, outcome)

    status = _run(source, answer)
    if status == 0 and outcome.get("failed"):
        print("toptraj compare: every method failed (each one's error is in the comparison)", file=sys.stderr)
        return 1
    return status


def plot(source: str, output: str, methods: list[str] | None = None) -> int:
    """``toptraj plot FILE|- -o OUT.html [--methods a,b]``: the page's plots of one trajectory
    request or cell (``toptraj.service.cell_plots``), or of every method of a compare body drawn over each other (``--methods`` turns a
    trajectory body into one), in a self-contained HTML file (Plotly's JavaScript inlined: it
    opens offline)."""
    from toptraj.planners.execution.deadline import NO_DEADLINE
    from toptraj.service.planning import plan_request
    from toptraj.service.plots import figures_html
    from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest

    def page(text: str) -> bytes:
        if _is_cell(text) and methods is None:
            return _cell(text, page=True)
        if methods is not None or _is_compare(text):
            text = _no_cell(text, "--methods compares timing methods of one arm's path")
            from toptraj.service.compare_plots import compare_html

            return compare_html(CompareRequest.model_validate_json(compare_body(text, methods)), NO_DEADLINE).encode()
        return figures_html(plan_request(TrajectoryRequest.model_validate_json(text))).encode()

    unwritable = _unwritable(output)
    if unwritable:  # said before planning, which may take minutes
        print(json.dumps(_problem("Cannot write the page", 400, f"{output!r}: {unwritable}")), file=sys.stderr)
        return 2
    buffer = io.BytesIO()
    status = _run(source, page, out=buffer)
    if status != 0:
        return status
    try:
        with open(output, "wb") as handle:
            handle.write(buffer.getvalue())
        return 0
    except OSError as error:
        print(json.dumps(_problem("Cannot write the page", 400, f"{output!r}: {error}")), file=sys.stderr)
        return 2


def _unwritable(output: str) -> str | None:
    """Why no file can be written at ``output``, or ``None``."""
    directory = os.path.dirname(os.path.abspath(output))
    if os.path.isdir(output):
        return "is a directory: give a file's path"
    if not os.path.isdir(directory):
        return f"its directory {directory!r} does not exist"
    if not os.access(output if os.path.exists(output) else directory, os.W_OK):
        return "cannot be written (permission denied)"
    return None
