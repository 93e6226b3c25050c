"""The durable store of uploaded URDFs: one SQLite database, ``uploads.sqlite3``, in the data
directory.

Why SQLite (Python's standard library) rather than files: an upload must check the name and the
caps and then write, and two worker processes may upload at once. A transaction (``BEGIN
IMMEDIATE``) makes that check-then-write atomic across processes without lock files, and a
commit is atomic and durable (write-ahead log), which is what "write a temporary file, then
``os.replace``" gives for one file but not for a file plus an index. The text is still content
addressed: ``urdfs`` holds each distinct text once under its SHA-256, ``robots`` maps names to
digests, so two names for one text store it once, each with its own options (locked joints,
joint_limits.yaml: ``toptraj.robots.upload_options``, as canonical JSON; "" for none). A database
written before options existed gets the column on first use, its uploads with no options.

Nothing is cached here: every call opens its own connection, so a process sees what another
process committed, and a forked worker never shares a connection with its parent.
"""

from __future__ import annotations

import os
import sqlite3
import time
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager
from dataclasses import dataclass
from pathlib import Path

from toptraj.robots.errors import RobotConflict, UploadStoreFull, UploadStoreUnavailable, excerpt
from toptraj.robots.sqlite_file import connected

DEFAULT_MAX_UPLOADS = 1_000
DEFAULT_MAX_BYTES = 200_000_000
DATABASE = "uploads.sqlite3"

_SCHEMA = """
CREATE TABLE IF NOT EXISTS urdfs (
    digest TEXT PRIMARY KEY,      -- SHA-256 of the UTF-8 text, hex
    urdf TEXT NOT NULL,
    bytes INTEGER NOT NULL        -- length of the UTF-8 text
);
CREATE TABLE IF NOT EXISTS robots (
    name TEXT PRIMARY KEY,
    digest TEXT NOT NULL REFERENCES urdfs (digest),
    dof INTEGER NOT NULL,
    created REAL NOT NULL,        -- Unix time, s
    options TEXT NOT NULL DEFAULT ''  -- toptraj.robots.upload_options.UploadOptions.to_json()
);
"""


def _migrate(connection: sqlite3.Connection) -> None:
    """Add the ``options`` column to a database written before it existed."""
    columns = [row[1] for row in connection.execute("PRAGMA table_info(robots)")]
    if columns and "options" not in columns:
        connection.execute("ALTER TABLE robots ADD COLUMN options TEXT NOT NULL DEFAULT ''")


def default_data_dir() -> Path:
    """``$TOPTRAJ_DATA_DIR``, else ``$XDG_DATA_HOME/toptraj``, else ``~/.local/share/toptraj``."""
    explicit = os.environ.get("TOPTRAJ_DATA_DIR")
    if explicit:
        return Path(explicit).expanduser()
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base) / "toptraj"


@dataclass(frozen=True)
class StoredUpload:
    """One stored upload: its name, the SHA-256 of its text, its degrees of freedom, when it
    was stored (Unix time, s) and its options (canonical JSON, "" for none)."""

    name: str
    digest: str
    dof: int
    created: float
    options: str = ""


@dataclass(frozen=True)
class StoreUsage:
    """What the store holds against its caps: uploads (names) and bytes of distinct texts."""

    uploads: int
    bytes: int
    max_uploads: int
    max_bytes: int


class UploadStore:
    """Uploaded URDF texts by name, in ``data_dir / "uploads.sqlite3"``, capped at
    ``max_uploads`` names and ``max_bytes`` bytes of distinct texts.

    Reading never creates anything: a store whose database does not exist yet is empty.
    """

    def __init__(self, data_dir: Path | str, max_uploads: int = DEFAULT_MAX_UPLOADS, max_bytes: int = DEFAULT_MAX_BYTES):
        self.data_dir = Path(data_dir)
        self.max_uploads = max_uploads
        self.max_bytes = max_bytes
        self.path = self.data_dir / DATABASE

    def __repr__(self) -> str:
        return f"UploadStore({str(self.path)!r}, max_uploads={self.max_uploads}, max_bytes={self.max_bytes})"

    @contextmanager
    def _write(self) -> Iterator[sqlite3.Connection]:
        """A writing connection (``_connect``), which creates the database when it is missing."""
        with self._connect(write=True) as connection:
            assert connection is not None
            yield connection

    def _connect(self, write: bool) -> AbstractContextManager[sqlite3.Connection | None]:
        """A connection in autocommit mode (``None`` when reading a store that does not exist).

        Raises:
            UploadStoreUnavailable: SQLite or the file system failed, here or in the block.
        """
        return connected(self.path, _SCHEMA, write, UploadStoreUnavailable, "the upload store", _migrate)

    def digest(self, name: str) -> str | None:
        """SHA-256 of the text stored under ``name``, ``None`` when there is none."""
        key = self.key(name)
        return None if key is None else key[0]

    def key(self, name: str) -> tuple[str, str] | None:
        """``(digest, options)`` stored under ``name`` (what a built model depends on), ``None``
        when there is none."""
        with self._connect(write=False) as connection:
            if connection is None:
                return None
            row = connection.execute(f"SELECT digest, {self._options(connection)} FROM robots WHERE name = ?", (name,)).fetchone()
        return None if row is None else (row[0], row[1])

    def read(self, name: str) -> tuple[str, str, str] | None:
        """``(digest, text, options)`` stored under ``name``, ``None`` when there is none."""
        with self._connect(write=False) as connection:
            if connection is None:
                return None
            row = connection.execute(
                f"SELECT robots.digest, urdfs.urdf, {self._options(connection)} FROM robots JOIN urdfs USING (digest) "
                "WHERE name = ?",
                (name,),
            ).fetchone()
        return None if row is None else (row[0], row[1], row[2])

    def alike(self, name: str) -> str | None:
        """The stored name that differs from ``name`` only in case (``NAME_PATTERN`` is ASCII),
        ``None`` when there is none."""
        with self._connect(write=False) as connection:
            if connection is None:
                return None
            return _alike(connection, name)

    def uploads(self) -> list[StoredUpload]:
        """Every stored upload, by name."""
        with self._connect(write=False) as connection:
            if connection is None:
                return []
            rows = connection.execute(
                f"SELECT name, digest, dof, created, {self._options(connection)} FROM robots ORDER BY name"
            ).fetchall()
        return [StoredUpload(*row) for row in rows]

    @staticmethod
    def _options(connection: sqlite3.Connection) -> str:
        """The options column as a SELECT reads it: '' from a database written before options
        existed (reading never writes; the next write adds the column)."""
        columns = [row[1] for row in connection.execute("PRAGMA table_info(robots)")]
        return "options" if "options" in columns else "''"

    def usage(self) -> StoreUsage:
        """How many uploads and bytes the store holds, with its caps."""
        with self._connect(write=False) as connection:
            count, size = (0, 0) if connection is None else self._usage(connection)
        return StoreUsage(count, size, self.max_uploads, self.max_bytes)

    @staticmethod
    def _usage(connection: sqlite3.Connection) -> tuple[int, int]:
        count = connection.execute("SELECT COUNT(*) FROM robots").fetchone()[0]
        size = connection.execute("SELECT COALESCE(SUM(bytes), 0) FROM urdfs").fetchone()[0]
        return count, size

    def put(self, name: str, digest: str, urdf: str, dof: int, options: str = "") -> bool:
        """Store ``urdf`` (whose SHA-256 is ``digest``) under ``name`` with ``options``, atomically.

        Returns:
            ``True`` when stored, ``False`` when ``name`` already held this very text and options.

        Raises:
            RobotConflict: ``name`` holds a different text or different options.
            UploadStoreFull: storing it would pass the count or byte cap.
        """
        size = len(urdf.encode())
        with self._write() as connection:
            connection.execute("BEGIN IMMEDIATE")
            try:
                row = connection.execute("SELECT digest, options FROM robots WHERE name = ?", (name,)).fetchone()
                if row is not None:
                    if row[0] != digest or row[1] != options:
                        what = "URDF" if row[0] != digest else "set of options (locked joints, joint limits)"
                        raise RobotConflict(
                            f"name {excerpt(name)} already holds a different {what}; choose another name, or delete it first",
                            rule="name_taken", name=name, what=what,
                        )
                    connection.execute("ROLLBACK")
                    return False
                alike = _alike(connection, name)  # the name itself is not stored (row is None)
                if alike is not None:  # a request naming one, mistyped in case, would plan the other
                    raise RobotConflict(f"name {excerpt(name)} differs from the upload {alike!r} only in case; choose another")
                count, stored = self._usage(connection)
                known = connection.execute("SELECT 1 FROM urdfs WHERE digest = ?", (digest,)).fetchone()
                added = 0 if known else size
                if count + 1 > self.max_uploads or stored + added > self.max_bytes:
                    raise UploadStoreFull(
                        f"the upload store holds {count} uploads and {stored} bytes; its caps are "
                        f"{self.max_uploads} uploads and {self.max_bytes} bytes, and this upload adds {added} bytes",
                        rule="store_full", count=count, size=stored, max_uploads=self.max_uploads, max_bytes=self.max_bytes,
                        added=added,
                    )
                if not known:
                    connection.execute("INSERT INTO urdfs (digest, urdf, bytes) VALUES (?, ?, ?)", (digest, urdf, size))
                connection.execute(
                    "INSERT INTO robots (name, digest, dof, created, options) VALUES (?, ?, ?, ?, ?)",
                    (name, digest, dof, time.time(), options),
                )
                connection.execute("COMMIT")
            except BaseException:
                if connection.in_transaction:
                    connection.execute("ROLLBACK")
                raise
        return True

    def delete(self, name: str) -> bool:
        """Remove ``name`` (and its text when no other name uses it); ``False`` if absent."""
        if not self.path.exists():
            return False
        with self._write() as connection:
            connection.execute("BEGIN IMMEDIATE")
            try:
                row = connection.execute("SELECT digest FROM robots WHERE name = ?", (name,)).fetchone()
                if row is None:
                    connection.execute("ROLLBACK")
                    return False
                connection.execute("DELETE FROM robots WHERE name = ?", (name,))
                connection.execute(
                    "DELETE FROM urdfs WHERE digest = ? AND NOT EXISTS (SELECT 1 FROM robots WHERE digest = ?)",
                    (row[0], row[0]),
                )
                connection.execute("COMMIT")
            except BaseException:
                if connection.in_transaction:
                    connection.execute("ROLLBACK")
                raise
            connection.execute("PRAGMA incremental_vacuum")  # give the freed pages back to the file system
        return True


def _alike(connection: sqlite3.Connection, name: str) -> str | None:
    """The name in ``robots`` equal to ``name`` but for case, ``None`` when there is none."""
    row = connection.execute("SELECT name FROM robots WHERE lower(name) = lower(?) AND name != ?", (name, name)).fetchone()
    return None if row is None else row[0]
