"""A SQLite database in a data directory, opened the same way by every store of the project
(the uploads, ``toptraj.robots.store``; the jobs, ``toptraj.service.jobs.store``): autocommit,
write-ahead log, incremental vacuum, its schema created on the first write, and every failure of
SQLite or the file system raised as the store's own "unavailable" error."""

from __future__ import annotations

import sqlite3
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from toptraj.robots.errors import ToptrajError, excerpt


@contextmanager
def connected(
    path: Path,
    schema: str,
    write: bool,
    unavailable: Callable[[str], ToptrajError],
    what: str,
    migrate: Callable[[sqlite3.Connection], None] | None = None,
) -> Iterator[sqlite3.Connection | None]:
    """A connection to the database at ``path`` in autocommit mode, ``None`` when reading one
    that does not exist; writing creates its directory and ``schema``; ``migrate`` is applied
    to every connection.

    Raises:
        ToptrajError: ``unavailable(detail)`` when SQLite or the file system failed, here or in
            the block (``what``: the store's name in that detail, e.g. "the job store").
    """
    if not write and not path.exists():
        yield None
        return
    try:
        if write:
            path.parent.mkdir(parents=True, exist_ok=True)
        connection = sqlite3.connect(path, timeout=30.0, isolation_level=None)
        try:
            if write:
                connection.execute("PRAGMA auto_vacuum = INCREMENTAL")  # takes effect on a new database
                connection.execute("PRAGMA journal_mode = WAL")
                connection.executescript(schema)
            if migrate is not None:
                migrate(connection)
            yield connection
        finally:
            connection.close()
    except (sqlite3.Error, OSError) as error:
        raise unavailable(
            f"{what} cannot be used ({type(error).__name__}: {excerpt(str(error), 120)}); "
            "its data directory (setting data_dir, TOPTRAJ_DATA_DIR) must be a writable directory"
        ) from error
