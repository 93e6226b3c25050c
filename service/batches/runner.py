"""The batch driver: request lines planned on Ray, results appended as they come.

Ray runs ``work.answer_chunk`` as tasks of ``CHUNK`` requests each (a typical request plans in
tens of milliseconds; a task costs about a millisecond of Ray's own), at most ``2 x workers``
tasks in flight, so memory stays bounded whatever the batch's length. Each result line carries
its request's line number and key; lines are written in the order they finish. What travels to
the workers: the request texts and the URDF texts of the uploaded robots the batch names (a
catalog robot is built by each worker from its own installation). What stays with the driver:
the output file, the upload store, the progress.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import robots
from robots.catalog import is_catalog_robot
from service.batches.lines import done_keys, read_requests

#: Requests per Ray task.
CHUNK = 4
#: Planning budget of one request in a batch, in s (as the synchronous endpoint's default).
BUDGET_S = 20.0


@dataclass(frozen=True)
class BatchReport:
    """What a run did: requests in the file, already done before it, planned now, seconds."""

    total: int
    skipped: int
    planned: int
    seconds: float

    @property
    def rate(self) -> float:
        """Requests planned per second by this run."""
        return self.planned / self.seconds if self.seconds > 0 else 0.0


def _uploads_named(texts: list[str]) -> dict[str, tuple[str, str]]:
    """URDF texts and options of the uploaded robots the requests name (catalog robots need none)."""
    names = set()
    for text in texts:
        try:
            body = json.loads(text)
        except ValueError:
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
        rate = done / seconds if seconds > 0 else 0.0
        left = (total - done) / rate if rate > 0 else float("nan")
        end = "\n" if done == total else ""
        stream.write(f"\r{done}/{total} requests, {rate:.1f}/s, {left:.0f} s left   {end}")
        stream.flush()

    return show


def _start_ray(address: str | None, workers: int | None):
    import ray

    if ray.is_initialized():
        return ray
    if address in (None, "local"):
        ray.init(
            num_cpus=workers or os.cpu_count() or 1,
            include_dashboard=False,
            object_store_memory=100 * 1024 * 1024,
            log_to_driver=False,
            configure_logging=False,
        )
    else:
        ray.init(address=address, log_to_driver=False, configure_logging=False)
    return ray


def run_batch(
    requests_path: Path | str,
    output_path: Path | str,
    workers: int | None = None,
    ray_address: str | None = None,
    progress: Callable[[int, int, float], None] | None = None,
    budget_s: float = BUDGET_S,
) -> BatchReport:
    """Plan every request of ``requests_path`` not yet answered in ``output_path`` and append
    their result lines to it. ``ray_address``: ``None``/``"local"`` starts a local Ray with
    ``workers`` CPUs (default: the cores), else an existing cluster (``auto`` or
    ``ray://host:port``)."""
    from service.batches.work import answer_chunk

    started = time.perf_counter()
    requests_path, output_path = Path(requests_path), Path(output_path)
    requests = read_requests(requests_path)
    done = done_keys(output_path)
    todo = [r for r in requests if r.key not in done]
    todo = list({r.key: r for r in todo}.values())  # a request repeated in the file is planned once
    skipped = len(requests) - len(todo)
    if not todo:
        return BatchReport(len(requests), skipped, 0, time.perf_counter() - started)
    ray = _start_ray(ray_address, workers)
    remote = ray.remote(num_cpus=1, max_retries=2)(answer_chunk)
    uploads = ray.put(_uploads_named([r.text for r in todo]))
    chunks = [[(r.key, r.text, r.number) for r in todo[k : k + CHUNK]] for k in range(0, len(todo), CHUNK)]
    window = 2 * int(ray.available_resources().get("CPU", workers or 1) or 1) + 1
    pending: list = []
    next_chunk, finished = 0, 0
    with open(output_path, "ab") as out:
        while pending or next_chunk < len(chunks):
            while next_chunk < len(chunks) and len(pending) < window:
                pending.append(remote.remote(chunks[next_chunk], uploads, budget_s))
                next_chunk += 1
            ready, pending = ray.wait(pending, num_returns=1)
            for line in ray.get(ready[0]):
                out.write(line)
                finished += 1
            out.flush()
            if progress:
                progress(finished, len(todo), time.perf_counter() - started)
    return BatchReport(len(requests), skipped, len(todo), time.perf_counter() - started)
