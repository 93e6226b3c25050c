"""The durable job store: one SQLite database, ``jobs.sqlite3``, in the data directory (beside
the upload store, ``robots/store.py``, and in its style).

Every server process on the same data directory shares it (write-ahead log; every call opens
its own connection): a job submitted to one process may run in another, and a ``DELETE`` in a
third cancels it. Transitions are single conditional updates (``... WHERE status = 'running'
AND owner = ?``) or ``BEGIN IMMEDIATE`` transactions, so two processes never both claim a job,
and a job cancelled while it runs stays cancelled whatever its runner writes afterwards.

A job's life: ``queued`` -> ``running`` -> ``done`` | ``failed``; ``queued`` or ``running`` ->
``cancelled`` (``DELETE``); ``running`` -> ``interrupted`` when the process running it stopped
(at its shutdown, or found dead by another runner: its process is gone, or its heartbeat is
older than ``STALE_S``). Queued jobs survive a restart and run when a runner is free.

What is kept is bounded: at most ``max_jobs`` jobs, none finished longer ago than ``max_age_s``,
and at most ``max_bytes`` of requests, results and errors together; the jobs that finished
first go first (``prune``). A result is at most half of ``max_bytes`` (``jobs.job_answer_bytes``: its
planning refuses larger bodies), so the newest job always fits.
"""

from __future__ import annotations

import json
import sqlite3
import time
import uuid
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path

from toptraj.robots.sqlite_file import connected
from toptraj.service.jobs.records import ClaimedJob, Job, JobEnded, JobQueueFull, JobStoreUnavailable, owner_is_gone

DATABASE = "jobs.sqlite3"
STATUSES = ("queued", "running", "done", "failed", "cancelled", "interrupted")
#: Statuses of a job that has ended (kept until pruned; never changes again).
ENDED = ("done", "failed", "cancelled", "interrupted")
#: Seconds without a heartbeat after which a running job counts as interrupted.
STALE_S = 30.0

_SCHEMA = """
CREATE TABLE IF NOT EXISTS jobs (
    seq INTEGER PRIMARY KEY AUTOINCREMENT,  -- order of submission; the list cursor
    id TEXT NOT NULL UNIQUE,                -- 32 hex digits (UUID4)
    kind TEXT NOT NULL,                     -- "trajectory", "compare"
    request TEXT NOT NULL,                  -- the validated request body, JSON
    budget_s REAL NOT NULL,                 -- computing time allowed once running, s
    status TEXT NOT NULL,
    fraction REAL NOT NULL DEFAULT 0.0,     -- progress in [0, 1]
    stage TEXT NOT NULL DEFAULT '',
    created REAL NOT NULL,                  -- Unix time, s
    started REAL,
    finished REAL,
    heartbeat REAL,                         -- last sign of life of the running job's runner
    owner TEXT,                             -- runner of a running job: host|pid|token
    result BLOB,                            -- the answer's JSON body, as the synchronous endpoint's
    error TEXT,                             -- problem+json object, JSON
    bytes INTEGER NOT NULL                  -- length of request, result and error together
);
CREATE INDEX IF NOT EXISTS jobs_by_status ON jobs (status, seq);
"""

_SUMMARY = "id, kind, status, fraction, stage, budget_s, created, started, finished, error, seq"


class JobStore:
    """Jobs in ``data_dir / "jobs.sqlite3"``, bounded by ``max_jobs`` jobs, ``max_age_s``
    seconds since a job ended and ``max_bytes`` bytes of requests, results and errors.

    Reading never creates anything: a store whose database does not exist yet is empty.
    """

    def __init__(
        self, data_dir: Path | str, max_jobs: int = 1_000, max_age_s: float = 7 * 86_400.0, max_bytes: int = 1_000_000_000
    ):
        self.data_dir = Path(data_dir)
        self.path = self.data_dir / DATABASE
        self.max_jobs, self.max_age_s, self.max_bytes = max_jobs, max_age_s, max_bytes

    def __repr__(self) -> str:
        bounds = f"max_jobs={self.max_jobs}, max_age_s={self.max_age_s}, max_bytes={self.max_bytes}"
        return f"JobStore({str(self.path)!r}, {bounds})"

    @contextmanager
    def _write(self) -> Iterator[sqlite3.Connection]:
        """A writing connection (``_connect``), which creates the database when it is missing."""
        with self._connect(write=True) as connection:
            assert connection is not None
            yield connection

    def _connect(self, write: bool) -> AbstractContextManager[sqlite3.Connection | None]:
        """A connection in autocommit mode (``None`` when reading a store that does not exist).

        Raises:
            JobStoreUnavailable: SQLite or the file system failed, here or in the block.
        """
        return connected(self.path, _SCHEMA, write, JobStoreUnavailable, "the job store")

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        """A write transaction (``BEGIN IMMEDIATE``): committed at the end of the block, rolled
        back on an error."""
        with self._write() as connection:
            connection.execute("BEGIN IMMEDIATE")
            try:
                yield connection
                connection.execute("COMMIT")
            except BaseException:
                if connection.in_transaction:
                    connection.execute("ROLLBACK")
                raise

    # Clients ------------------------------------------------------------------------------
    def submit(self, kind: str, request: str, budget_s: float, max_queued: int) -> Job:
        """Queue a job computing ``request`` (JSON) of ``kind`` within ``budget_s`` seconds.

        Raises:
            JobQueueFull: ``max_queued`` jobs wait already.
        """
        job_id = uuid.uuid4().hex
        with self._transaction() as connection:
            queued = connection.execute("SELECT COUNT(*) FROM jobs WHERE status = 'queued'").fetchone()[0]
            if queued >= max_queued:
                raise JobQueueFull(
                    f"{queued} jobs wait already, as many as this service queues; submit again later "
                    "(GET /v1/jobs?status=queued lists them, DELETE /v1/jobs/{id} cancels one)"
                )
            connection.execute(
                "INSERT INTO jobs (id, kind, request, budget_s, status, created, bytes) VALUES (?, ?, ?, ?, 'queued', ?, ?)",
                (job_id, kind, request, budget_s, time.time(), len(request.encode())),
            )
            pruned = self._prune(connection)
        if pruned:
            self._vacuum()
        job = self.get(job_id)
        assert job is not None  # just stored; pruning removes finished jobs only
        return job

    def get(self, job_id: str) -> Job | None:
        """The job ``job_id``, ``None`` when there is none."""
        with self._connect(write=False) as connection:
            if connection is None:
                return None
            row = connection.execute(f"SELECT {_SUMMARY} FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else Job.from_row(row)

    def result(self, job_id: str) -> bytes | None:
        """The JSON body of the answer of job ``job_id`` when it is done, else ``None``."""
        with self._connect(write=False) as connection:
            if connection is None:
                return None
            row = connection.execute("SELECT result FROM jobs WHERE id = ? AND status = 'done'", (job_id,)).fetchone()
        return None if row is None else bytes(row[0])

    def request(self, job_id: str) -> str | None:
        """The validated request (JSON) of job ``job_id``, ``None`` when there is none."""
        with self._connect(write=False) as connection:
            if connection is None:
                return None
            row = connection.execute("SELECT request FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else str(row[0])

    def jobs(self, limit: int, before: int | None = None, status: str | None = None) -> list[Job]:
        """At most ``limit`` jobs, newest first, submitted before the job of sequence number
        ``before`` (when given), with ``status`` (when given)."""
        clauses: list[str] = []
        values: list[int | str] = []
        if before is not None:
            clauses.append("seq < ?")
            values.append(before)
        if status is not None:
            clauses.append("status = ?")
            values.append(status)
        where = f"WHERE {' AND '.join(clauses)}" if clauses else ""
        with self._connect(write=False) as connection:
            if connection is None:
                return []
            rows = connection.execute(
                f"SELECT {_SUMMARY} FROM jobs {where} ORDER BY seq DESC LIMIT ?", (*values, limit)
            ).fetchall()
        return [Job.from_row(row) for row in rows]

    def cancel(self, job_id: str) -> Job | None:
        """Cancel job ``job_id`` if it is queued or running (a running job's runner stops its
        work when it sees the status); a cancelled job stays cancelled. ``None`` if unknown.

        Raises:
            JobEnded: the job is done, failed or interrupted.
        """
        if not self.path.exists():
            return None
        with self._write() as connection:
            connection.execute(
                "UPDATE jobs SET status = 'cancelled', finished = ?, owner = NULL "
                "WHERE id = ? AND status IN ('queued', 'running')",
                (time.time(), job_id),
            )
        job = self.get(job_id)
        if job is not None and job.status != "cancelled":
            raise JobEnded(f"job {job_id} has ended already (status {job.status}); there is nothing to cancel")
        return job

    def delete(self, job_id: str) -> bool:
        """Delete job ``job_id`` with its stored result and error if it has ended; whether one
        was deleted (``False``: no such job, or it has not ended)."""
        if not self.path.exists():
            return False
        ended = ", ".join(repr(status) for status in ENDED)
        with self._transaction() as connection:
            deleted = connection.execute(f"DELETE FROM jobs WHERE id = ? AND status IN ({ended})", (job_id,)).rowcount
        if deleted:
            self._vacuum()
        return bool(deleted)

    # Runners ------------------------------------------------------------------------------
    def has_queued(self) -> bool:
        """Whether some job waits (a cheap read, before claiming)."""
        with self._connect(write=False) as connection:
            if connection is None:
                return False
            return connection.execute("SELECT 1 FROM jobs WHERE status = 'queued' LIMIT 1").fetchone() is not None

    def claim(self, owner: str, max_running: int) -> ClaimedJob | None:
        """The oldest queued job, now running under ``owner``, unless ``max_running`` jobs run
        already (in every process on this store) or none waits."""
        with self._transaction() as connection:
            running = connection.execute("SELECT COUNT(*) FROM jobs WHERE status = 'running'").fetchone()[0]
            if running >= max_running:
                return None
            row = connection.execute(
                "SELECT id, kind, request, budget_s FROM jobs WHERE status = 'queued' ORDER BY seq LIMIT 1"
            ).fetchone()
            if row is None:
                return None
            now = time.time()
            connection.execute(
                "UPDATE jobs SET status = 'running', started = ?, heartbeat = ?, owner = ?, stage = 'starting' WHERE id = ?",
                (now, now, owner, row[0]),
            )
        return ClaimedJob(*row)

    def report(self, job_id: str, owner: str, fraction: float, stage: str) -> None:
        """Record the progress of a running job of ``owner``."""
        with self._write() as connection:
            connection.execute(
                "UPDATE jobs SET fraction = ?, stage = ?, heartbeat = ? WHERE id = ? AND owner = ? AND status = 'running'",
                (fraction, stage[:200], time.time(), job_id, owner),
            )

    def heartbeat(self, owner: str, job_ids: list[str]) -> set[str]:
        """Mark the running jobs of ``owner`` alive; returns those of ``job_ids`` that no longer
        run under ``owner`` (cancelled, or taken as interrupted): their work must stop."""
        with self._write() as connection:
            connection.execute("UPDATE jobs SET heartbeat = ? WHERE owner = ? AND status = 'running'", (time.time(), owner))
            marks = ",".join("?" * len(job_ids))
            running = {
                row[0]
                for row in connection.execute(
                    f"SELECT id FROM jobs WHERE id IN ({marks}) AND owner = ? AND status = 'running'", (*job_ids, owner)
                )
            }
        return set(job_ids) - running

    def finish(self, job_id: str, owner: str, status: str, result: bytes | None = None, error: dict | None = None) -> bool:
        """End a running job of ``owner`` as ``status`` (done, failed, interrupted) with its
        ``result`` or ``error``; ``False`` when it no longer ran under ``owner`` (cancelled)."""
        error_text = None if error is None else json.dumps(error)
        size = len(result or b"") + len((error_text or "").encode())
        with self._transaction() as connection:
            changed = connection.execute(
                "UPDATE jobs SET status = ?, finished = ?, result = ?, error = ?, owner = NULL, "
                "fraction = CASE WHEN ? = 'done' THEN 1.0 ELSE fraction END, "
                "stage = CASE WHEN ? = 'done' THEN 'done' ELSE stage END, bytes = bytes + ? "
                "WHERE id = ? AND owner = ? AND status = 'running'",
                (status, time.time(), result, error_text, status, status, size, job_id, owner),
            ).rowcount
            pruned = self._prune(connection)
        if pruned:
            self._vacuum()
        return bool(changed)

    def interrupt_orphans(self, live_tokens: set[str], error: dict, stale_s: float = STALE_S) -> list[str]:
        """Mark as interrupted every running job whose runner is gone (its process no longer
        exists, or its heartbeat is older than ``stale_s``); returns their ids."""
        if not self.path.exists():
            return []
        now = time.time()
        with self._transaction() as connection:
            rows = connection.execute("SELECT id, owner, heartbeat FROM jobs WHERE status = 'running'").fetchall()
            orphans = [
                job_id
                for job_id, owner, heartbeat in rows
                if owner_is_gone(owner, live_tokens) or heartbeat is None or heartbeat < now - stale_s
            ]
            text = json.dumps(error)
            for job_id in orphans:
                connection.execute(
                    "UPDATE jobs SET status = 'interrupted', finished = ?, error = ?, owner = NULL, bytes = bytes + ? "
                    "WHERE id = ? AND status = 'running'",
                    (now, text, len(text.encode()), job_id),
                )
        return orphans

    def interrupt(self, owner: str, error: dict) -> None:
        """Mark every job still running under ``owner`` as interrupted (its runner stops)."""
        if not self.path.exists():
            return
        text = json.dumps(error)
        with self._write() as connection:
            connection.execute(
                "UPDATE jobs SET status = 'interrupted', finished = ?, error = ?, owner = NULL, bytes = bytes + ? "
                "WHERE owner = ? AND status = 'running'",
                (time.time(), text, len(text.encode()), owner),
            )

    # Bounds ---------------------------------------------------------------------------------
    def prune(self) -> None:
        """Delete ended jobs beyond the bounds (count, age, bytes), oldest first."""
        if not self.path.exists():
            return
        with self._transaction() as connection:
            pruned = self._prune(connection)
        if pruned:
            self._vacuum()

    def _prune(self, connection: sqlite3.Connection) -> int:
        """Delete ended jobs beyond the bounds in ``connection``'s transaction; returns how many."""
        ended = f"status IN ({', '.join(repr(status) for status in ENDED)})"
        oldest = time.time() - self.max_age_s
        deleted = connection.execute(f"DELETE FROM jobs WHERE {ended} AND finished < ?", (oldest,)).rowcount
        count, size = connection.execute("SELECT COUNT(*), COALESCE(SUM(bytes), 0) FROM jobs").fetchone()
        if count <= self.max_jobs and size <= self.max_bytes:
            return deleted
        # The jobs that ended first go until both bounds hold (queued and running ones stay): a
        # job submitted early that has just ended keeps its answer over one read long ago.
        doomed = []
        for seq, job_bytes in connection.execute(f"SELECT seq, bytes FROM jobs WHERE {ended} ORDER BY finished, seq"):
            if count <= self.max_jobs and size <= self.max_bytes:
                break
            doomed.append((seq,))
            count, size = count - 1, size - job_bytes
        connection.executemany("DELETE FROM jobs WHERE seq = ?", doomed)
        return deleted + len(doomed)

    def _vacuum(self) -> None:
        """Give pages freed by deletions back to the file system."""
        with self._write() as connection:
            connection.execute("PRAGMA incremental_vacuum")

    def usage(self) -> tuple[int, int]:
        """(jobs, bytes) the store holds."""
        with self._connect(write=False) as connection:
            if connection is None:
                return 0, 0
            return connection.execute("SELECT COUNT(*), COALESCE(SUM(bytes), 0) FROM jobs").fetchone()
