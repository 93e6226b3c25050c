"""``toptraj batch FILE -o OUT``: a file of requests planned on Ray, one result line per line,
resumable (``toptraj.service.batches``)."""

from __future__ import annotations

import json
import os
import sys

from toptraj.service.commands import _problem


def _not_regular(path: str, role: str) -> str | None:
    """Why ``path`` cannot be a batch's ``role`` ("requests" or "output"), or ``None``: a batch
    reads its request file twice (its lines counted, then planned) and resumes from its output,
    so both are regular files (standard input, a pipe or a device is none)."""
    if path != "-" and (not os.path.exists(path) or os.path.isfile(path)):
        return None
    if role == "requests":
        return (
            f"the request file {path!r} is not a regular file: a batch reads its lines twice (counted, then planned) "
            "and resumes by line number; write them to a file first (e.g. ... > requests.jsonl) and give its path"
        )
    return (
        f"the output {path!r} is not a regular file: a batch appends its result lines to it and resumes from it; "
        "give a file's path (e.g. -o results.jsonl), then read it (cat results.jsonl)"
    )


def _refused(requests: str, output: str, workers: int | None, budget_s: float | None) -> tuple[str, int, str] | None:
    """(title, status, detail) of the options or files a batch cannot take, or ``None``."""
    from toptraj.service.batches.runner import MAX_BUDGET_S

    if workers is not None and workers < 1:
        return "Invalid option", 400, f"--workers must be at least 1, not {workers}"
    if budget_s is not None and not 0.0 < budget_s <= MAX_BUDGET_S:  # NaN too
        return "Invalid option", 400, f"--budget must be in (0, {MAX_BUDGET_S:g}] s, not {budget_s:g}"
    for path, role in ((requests, "requests"), (output, "output")):
        problem = _not_regular(path, role)
        if problem:
            return "Cannot read or write", 400, problem
    return None


def batch(
    requests: str,
    output: str,
    workers: int | None,
    ray_address: str | None,
    budget_s: float | None = None,
    retry_failed: bool = False,
) -> int:
    """``toptraj batch FILE -o OUT``: every request line planned (on Ray), one result line per
    line, resumable (``toptraj.service.batches``). Ctrl-C stops within seconds, keeps what finished,
    prints the command that resumes and exits with 130; a second Ctrl-C changes nothing."""
    import shlex
    import signal
    import threading

    from toptraj.service.batches import run_batch
    from toptraj.service.batches.lines import ForeignOutput
    from toptraj.service.batches.ray_pool import RayClientMissing, RayMissing, RayUnreachable
    from toptraj.service.batches.runner import BUDGET_S, progress_bar

    refused = _refused(requests, output, workers, budget_s)
    if refused:
        print(json.dumps(_problem(*refused)), file=sys.stderr)
        return 2
    budget = BUDGET_S if budget_s is None else budget_s
    stop = threading.Event()

    def interrupted(signum, frame) -> None:
        if not stop.is_set():  # a raw write: the handler may interrupt a write to sys.stderr
            os.write(2, b"\nstopping: keeping the finished lines, cancelling the others ...\n")
        stop.set()

    previous = signal.signal(signal.SIGINT, interrupted)
    try:
        report = run_batch(requests, output, workers, ray_address, progress_bar(), budget, retry_failed, stop)
    except (RayMissing, RayUnreachable, ForeignOutput, OSError) as error:
        titles = {
            RayMissing: "Ray is not installed", RayClientMissing: "Ray Client is not installed",
            RayUnreachable: "Ray cluster unreachable", ForeignOutput: "Not a result file",
        }
        print(json.dumps(_problem(titles.get(type(error), "Cannot read or write"), 400, str(error))), file=sys.stderr)
        return 2
    finally:
        signal.signal(signal.SIGINT, previous)
    summary = _batch_summary(report, output)
    if not report.interrupted:
        print(summary, file=sys.stderr)
        if report.total == 0:
            print(f"toptraj batch: {requests} holds no line: give a file of one request body per line", file=sys.stderr)
        return 0
    command = ["toptraj", "batch", requests, "-o", output]
    for option, value in (("--workers", workers), ("--ray-address", ray_address), ("--budget", budget_s)):
        if value is not None:
            command += [option, f"{value:g}" if isinstance(value, float) else str(value)]
    print(f"interrupted: {summary}\nresume with: {shlex.join(command)}", file=sys.stderr)
    return 130


def _batch_summary(report, output: str) -> str:
    """What a batch did: lines answered, found done, in all, its time and rate, and the Ray
    nodes that answered (when more than one)."""
    nodes = sorted(report.nodes.values(), reverse=True)
    return (
        f"{report.planned} answered, {report.skipped} already in {output}, {report.total} in all, "
        f"{report.seconds:.1f} s ({report.rate:.1f} lines/s)"
        + (f", on {len(nodes)} Ray nodes ({', '.join(map(str, nodes))} requests)" if len(nodes) > 1 else "")
    )
