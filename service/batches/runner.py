"""The batch driver: request lines planned on Ray, a result line per request line appended as
they come, and an interruption (Ctrl-C) that stops within seconds and leaves a file to resume.

Each line is read and checked as the tasks need more (``lines.read_requests``); a line that
cannot be read is written as its 4xx result at once. Identical requests (one key) are computed
once: a line of a request under way waits for its answer, and one of a request answered gets a
copy of its result line (``results.ResultWriter``). The others are planned by ``RayPool``: tasks
of ``CHUNK`` requests each (a typical request plans in tens of milliseconds; a task costs about
a millisecond of Ray's own), at most ``2 x workers + 1`` tasks in flight, and only their texts
are held, so memory stays bounded whatever the batch's length. What travels to the workers: the request texts and the
URDF texts of the uploaded robots the batch names (a catalog robot is built by each worker from
its own installation). What stays with the driver: the output file, the upload store, the
progress.

Resuming: the lines already answered in the output file are skipped by line number, but for
those whose request changed since (planned again in place of their result); with
``retry_failed``, those answered with a budget error (504) or another 5xx are planned again
(``lines.resume_output``). Stopping (``stop`` set, as ``toptraj batch`` does on Ctrl-C): no task
is submitted any more, the result lines of the tasks already finished are written, the others
are cancelled (their workers killed), and a Ray started here is shut down with its processes.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import orjson

from toptraj import robots
from toptraj.robots.catalog import is_catalog_robot
from toptraj.service.batches.lines import ForeignOutput, RequestLine, problem_body, read_requests, resume_output
from toptraj.service.batches.ray_pool import RayPool
from toptraj.service.batches.results import ResultWriter
from toptraj.service.budget_advice import advised_line, for_batch_line

#: Requests per Ray task.
CHUNK = 4
#: Planning budget of one request in a batch, in s (as the synchronous endpoint's default).
BUDGET_S = 20.0
#: Largest planning budget of one request, in s.
MAX_BUDGET_S = 3600.0
#: Time a task may take beyond its requests' budgets (a solver step that cannot check its
#: deadline), in s; past it the task is killed and its requests are 504 lines.
TASK_SLACK_S = 10.0
#: Time a task may take beyond that while no task of the run has answered yet, in s: Ray's
#: workers starting (a process each, importing the planning stack and preparing: ten seconds
#: and more on a busy machine) is no line's planning.
STARTUP_S = 60.0
#: Longest wait for a task before the driver looks at ``stop`` again, in s.
WAIT_S = 0.2

@dataclass(frozen=True)
class BatchReport:
    """What a run did: lines in the file, already answered before it, answered now (each
    line of a group of identical requests counted), seconds, whether it was stopped before
    the end (``stop``), and the requests each Ray node answered (by node id; identical
    requests counted once)."""

    total: int
    skipped: int
    planned: int
    seconds: float
    interrupted: bool = False
    nodes: dict[str, int] = field(default_factory=dict)

    @property
    def rate(self) -> float:
        """Lines answered per second by this run."""
        return self.planned / self.seconds if self.seconds > 0 else 0.0


def _uploads_named(texts: Sequence[str]) -> dict[str, tuple[str, str]]:
    """URDF texts and options of the uploaded robots the requests name (catalog robots need none)."""
    names = set()
    for text in texts:
        try:
            body = orjson.loads(text)
        except orjson.JSONDecodeError:
            continue
        if isinstance(body, dict) and isinstance(body.get("robot"), str) and not is_catalog_robot(body["robot"]):
            names.add(body["robot"])
    store = robots.upload_store()
    found = {}
    for name in sorted(names):
        stored = store.read(name)
        if stored is not None:
            found[name] = (stored[1], stored[2])
    return found


def progress_bar(stream: TextIO = sys.stderr) -> Callable[[int, int, float], None]:
    """A one-line progress display: count, rate and time left."""

    def show(done: int, total: int, seconds: float) -> None:
        if total == 0:  # a resumed batch whose every line has its result
            stream.write("nothing left to do: every request already has its result in the output\n")
            stream.flush()
            return
        rate = done / seconds if seconds > 0 else 0.0
        left = f", {(total - done) / rate:.0f} s left" if rate > 0 else ""
        end = "\n" if done == total else ""
        stream.write(f"\r{done}/{total} requests, {rate:.1f}/s{left}   {end}")
        stream.flush()

    return show


def _failed(chunk: list[tuple[str, str]], error: BaseException) -> list[tuple[str, int, bytes]]:
    """The 500 of each request of a task that failed as a whole (its worker died)."""
    detail = f"the worker planning this line failed ({type(error).__name__}); run the batch again with --retry-failed"
    return [(key, 500, problem_body(500, "Worker failed", detail)) for key, _ in chunk]


def _kill_overdue(runner, running: dict, started_at: dict, budget_s: float, results: ResultWriter, warm_at: float | None = 0.0) -> int:
    """Kill the tasks that ran past their requests' budgets plus ``TASK_SLACK_S`` (a solver
    step that cannot check its deadline), and ``STARTUP_S`` more for a task started before
    ``warm_at`` (when a task first answered since the run began or a worker was killed; ``None``:
    not yet): its worker may have been starting. Write their requests as 504 lines;
    how many lines were written. A task counts as started once it is among the
    ``runner.cpus`` oldest still running (Ray starts tasks in the order submitted, one per CPU)."""
    now = time.monotonic()
    for handle in list(running)[: runner.cpus]:
        started_at.setdefault(handle, now)
    def slack(since: float) -> float:
        return TASK_SLACK_S + (STARTUP_S if warm_at is None or since < warm_at else 0.0)

    overdue = [h for h, since in started_at.items() if now > since + len(running[h]) * budget_s + slack(since)]
    if not overdue:
        return 0
    runner.cancel(overdue)
    detail = (
        f"the planning did not end within its budget of {budget_s:g} s and was stopped; {for_batch_line(budget_s, MAX_BUDGET_S)}"
    )
    written = 0
    for handle in overdue:
        del started_at[handle]
        written += results.answers([(key, 504, problem_body(504, "Time budget exceeded", detail)) for key, _ in running.pop(handle)])
    return written


def count_lines(path: Path) -> int:
    """Lines of ``path`` (a last line without its newline counted)."""
    count, last = 0, b"\n"
    with open(path, "rb") as handle:
        while block := handle.read(1 << 20):
            count += block.count(b"\n")
            last = block[-1:]
    return count + (last != b"\n")


def run_batch(
    requests_path: Path | str,
    output_path: Path | str,
    workers: int | None = None,
    ray_address: str | None = None,
    progress: Callable[[int, int, float], None] | None = None,
    budget_s: float = BUDGET_S,
    retry_failed: bool = False,
    stop: threading.Event | None = None,
    pool: Callable[[], Any] | None = None,
) -> BatchReport:
    """Answer every line of ``requests_path`` not yet answered in ``output_path`` (with
    ``retry_failed``, nor answered with a 504 or another 5xx) and append their result lines to
    it, each request planned within ``budget_s`` s. ``ray_address``: ``None``/``"local"``
    starts a local Ray with ``workers`` CPUs (default: the cores), else an existing cluster
    (``auto`` or ``ray://host:port``); ``pool`` makes another pool (``RayPool``'s methods).
    Once ``stop`` is set the run ends within about a second, its finished results written
    (``BatchReport.interrupted``).

    Raises:
        RayMissing: Ray is not installed (and lines need planning).
        OSError: a file cannot be read or written.
        ForeignOutput: ``output_path`` is the request file, or holds lines that are no result
            lines (it is left as it is).
    """
    started = time.perf_counter()
    requests_path, output_path = Path(requests_path), Path(output_path)
    stop = stop or threading.Event()
    if output_path.exists() and requests_path.exists() and output_path.samefile(requests_path):
        raise ForeignOutput("--output is the request file itself; give another file for the results")
    total = count_lines(requests_path)
    done = resume_output(output_path, retry_failed, requests_path)
    skipped = sum(1 for number in done if number <= total)

    def report(written: int) -> None:
        if progress:
            progress(written, total - skipped, time.perf_counter() - started)

    with _no_empty_output_on_failure(output_path), open(output_path, "ab") as out:
        results = ResultWriter(out, output_path)
        lines = read_requests(requests_path, skip=set(done))
        runner: Any = None

        def make_runner() -> Any:
            nonlocal runner
            runner = (pool or (lambda: RayPool(ray_address, workers)))()
            return runner

        if total and not stop.is_set():
            report(0)  # "nothing left to do" where every line has its result
        try:
            interrupted = _plan_lines(lines, results, make_runner, budget_s, stop, report)
        finally:
            if runner is not None:
                runner.close()
    return BatchReport(
        total, skipped, results.written, time.perf_counter() - started, interrupted, dict(getattr(runner, "nodes", {}))
    )


@contextlib.contextmanager
def _no_empty_output_on_failure(output_path: Path) -> Iterator[None]:
    """Remove ``output_path`` where the run that created it fails before writing a result (a
    cluster that cannot be joined, say): no empty output left to mistake for one."""
    created = not output_path.exists()
    try:
        yield
    except BaseException:
        if created and output_path.exists() and output_path.stat().st_size == 0:
            output_path.unlink()
        raise


def _plan_lines(
    lines: Iterator[RequestLine], results: ResultWriter, make_runner: Callable[[], Any], budget_s: float,
    stop: threading.Event, report: Callable[[int], None],
) -> bool:
    """Every request of ``lines`` answered in ``results``, read as the tasks need them
    (``_Flight.read``), planned by the runner (``make_runner()``, made at the first request to
    plan) in chunks of ``CHUNK``, at most ``2 * runner.cpus + 1`` chunks at a time, a chunk
    past its budget answered 504. So only the texts of the chunks in flight are held, whatever
    the file's length. ``report(written)`` after each step that wrote; returns whether
    ``stop`` interrupted the run."""
    advice = for_batch_line(budget_s, MAX_BUDGET_S)
    flight = _Flight(make_runner, budget_s)
    while not stop.is_set():
        wrote = results.written
        exhausted = flight.read(lines, results, stop)
        if results.written > wrote:
            report(results.written)
        if not flight.running:
            if exhausted:
                break
            continue
        runner, running = flight.runner, flight.running
        ready, _ = runner.wait(list(running), WAIT_S)
        for handle in ready:
            flight.started_at.pop(handle, None)
            done = running.pop(handle)
            try:
                answers = runner.result(handle)
            except Exception as error:  # the task as a whole: a worker died
                if stop.is_set():
                    continue  # cancelled by the stop: resumed later
                answers = _failed(done, error)
            results.answers([(key, status, advised_line(status, body, advice)) for key, status, body in answers])
        overdue = _kill_overdue(runner, running, flight.started_at, budget_s, results, flight.warm_at)
        if overdue:  # their workers were killed: the tasks after them may wait for new ones
            flight.warm_at = None
        elif ready and flight.warm_at is None:  # the tasks started so far began while workers started
            flight.warm_at = time.monotonic()
        if ready or overdue:
            report(results.written)
    if flight.running:
        _collect_finished(flight.runner, flight.running, results, advice)
    results.out.flush()
    return bool(flight.running) or not flight.exhausted or bool(flight.chunk)


class _Flight:
    """The tasks of a run in flight (``running``: handle -> its chunk, in the order submitted),
    the chunk being gathered, and the uploads shared with the runner's tasks."""

    def __init__(self, make_runner: Callable[[], Any], budget_s: float):
        self.make_runner, self.budget_s = make_runner, budget_s
        self.runner: Any = None
        self.running: dict[Any, list[tuple[str, str]]] = {}
        self.started_at: dict[Any, float] = {}
        self.chunk: list[tuple[str, str]] = []
        self.uploads: dict[str, tuple[str, str]] = {}
        self.exhausted = False
        self.warm_at: float | None = None  # when a task first answered since the start or the last kill

    def read(self, lines: Iterator[RequestLine], results: ResultWriter, stop: threading.Event) -> bool:
        """Read lines until ``2 * cpus + 1`` tasks are in flight or the file ends: a line refused
        before planning answered at once, a line of a request under way or answered sharing its
        answer, the others gathered into chunks and submitted. Returns whether the file ended."""
        while not self.exhausted and (self.runner is None or len(self.running) < 2 * self.runner.cpus + 1) and not stop.is_set():
            line = next(lines, None)
            if line is None:
                self.exhausted = True
            elif line.problem is not None:
                results.write(line.number, line.key, *line.problem, shared=False)
            elif line.key in results.pending:
                results.pending[line.key].append(line.number)
            elif results.answered(line.key):
                results.copy(line.number, line.key)
            else:
                results.pending[line.key] = [line.number]
                self.chunk.append((line.key, line.text))
            if len(self.chunk) == CHUNK or (self.exhausted and self.chunk):
                self._submit()
        results.out.flush()
        return self.exhausted

    def _submit(self) -> None:
        """The chunk gathered as a task; the runner made at the first, and the uploads its
        requests name shared first where they are new."""
        fresh = self.runner is None
        self.runner = self.runner or self.make_runner()
        named = _uploads_named([text for _, text in self.chunk])
        if fresh or not named.keys() <= self.uploads.keys():  # the tasks from here on get every upload named so far
            self.uploads.update(named)
            self.runner.share(dict(self.uploads))
        self.running[self.runner.submit(self.chunk, self.budget_s)] = self.chunk
        self.chunk = []


def _collect_finished(runner, running: dict, results: ResultWriter, advice: str) -> None:
    """On a stop: the answers of the tasks already finished written (a 504 ending with
    ``advice``), the others cancelled (they are resumed later)."""
    ready, rest = runner.wait(list(running), 0) if running else ([], [])
    for handle in ready:
        try:
            results.answers([(key, status, advised_line(status, body, advice)) for key, status, body in runner.result(handle)])
        except Exception:  # noqa: S112 - cancelled or failed: resumed later
            continue
    runner.cancel(rest)
