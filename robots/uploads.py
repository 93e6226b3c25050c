"""Uploaded URDFs: checked at upload (``robots.urdf_check``), kept durably in an ``UploadStore``
(``robots.store``), and built into ``Robot`` objects on demand, of which a bounded LRU cache keeps
the most recently used. However many uploads the store holds, a process keeps at most
``cache_size`` upload models in memory.

Every lookup asks the store which text a name holds, so an upload, replacement or deletion made
by another process (or before a restart) is seen at once; the cache is keyed by name and digest
and never serves a text the store no longer holds under that name.

The process's store is set by ``configure_uploads`` (the service does it from its settings);
until then it is ``UploadStore(default_data_dir())`` with the default caps.
"""

from __future__ import annotations

import hashlib
import re
import threading
from collections import OrderedDict
from pathlib import Path

from robots.catalog import catalog_names, is_catalog_robot, robot_from_model
from robots.errors import CatalogRobotReadOnly, InvalidRobotName, InvalidURDF, RobotConflict, UnknownRobot, excerpt
from robots.robot import Robot
from robots.store import DEFAULT_MAX_BYTES, DEFAULT_MAX_UPLOADS, StoredUpload, UploadStore, default_data_dir
from robots.urdf_check import check_urdf

DEFAULT_CACHE_SIZE = 32
MAX_NAME_CHARS = 64
#: A name starts with a letter and holds at most 64 letters, digits, '_', '.' or '-'.
NAME_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_.-]{0,63}")


class _RobotCache:
    """Least-recently-used ``Robot`` objects keyed by ``(name, digest)``, at most ``size``."""

    def __init__(self, size: int):
        self.size = size
        self._robots: OrderedDict[tuple[str, str], Robot] = OrderedDict()

    def get(self, key: tuple[str, str]) -> Robot | None:
        robot = self._robots.get(key)
        if robot is not None:
            self._robots.move_to_end(key)
        return robot

    def put(self, key: tuple[str, str], robot: Robot) -> None:
        self.discard(key[0])
        self._robots[key] = robot
        while len(self._robots) > self.size:
            self._robots.popitem(last=False)

    def discard(self, name: str) -> None:
        for key in [key for key in self._robots if key[0] == name]:
            del self._robots[key]

    def __len__(self) -> int:
        return len(self._robots)


_lock = threading.Lock()
_store: UploadStore | None = None
_cache = _RobotCache(DEFAULT_CACHE_SIZE)


def configure_uploads(
    data_dir: Path | str | None = None,
    *,
    max_uploads: int = DEFAULT_MAX_UPLOADS,
    max_bytes: int = DEFAULT_MAX_BYTES,
    cache_size: int = DEFAULT_CACHE_SIZE,
) -> UploadStore:
    """Keep this process's uploads in ``data_dir`` (default ``default_data_dir()``), capped at
    ``max_uploads`` uploads and ``max_bytes`` bytes, with at most ``cache_size`` models built at
    a time. Empties the model cache. Returns the store."""
    global _store, _cache
    store = UploadStore(data_dir if data_dir is not None else default_data_dir(), max_uploads, max_bytes)
    with _lock:
        _store, _cache = store, _RobotCache(max(cache_size, 1))
    return store


def upload_store() -> UploadStore:
    """The store this process keeps uploads in."""
    global _store
    with _lock:
        if _store is None:
            _store = UploadStore(default_data_dir())
        return _store


def cached_upload_count() -> int:
    """How many upload models this process holds in memory (at most the cache size)."""
    with _lock:
        return len(_cache)


def check_name(name: str) -> None:
    """Raise ``InvalidRobotName`` unless ``name`` follows ``NAME_PATTERN``."""
    if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
        raise InvalidRobotName(
            f"name {excerpt(name)} must start with a letter and hold at most {MAX_NAME_CHARS} letters, "
            "digits, '_', '.' or '-'"
        )


def _build(name: str, digest: str, urdf: str) -> Robot:
    robot = robot_from_model(name, check_urdf(urdf), "upload", None)
    with _lock:
        _cache.put((name, digest), robot)
    return robot


def load_upload(name: str) -> Robot | None:
    """The uploaded robot ``name``, built from the store unless cached; ``None`` if the store
    holds no such name.

    Raises:
        InvalidURDF: the stored text no longer passes the checks (they became stricter).
    """
    store = upload_store()
    digest = store.digest(name)
    if digest is None:
        return None
    with _lock:
        robot = _cache.get((name, digest))
    if robot is not None:
        return robot
    stored = store.read(name)
    if stored is None:
        return None
    try:
        return _build(name, *stored)
    except InvalidURDF as error:
        raise InvalidURDF(f"the stored upload {excerpt(name)} no longer passes the checks: {error.detail}") from None


def register_urdf(urdf: str, name: str | None = None) -> Robot:
    """Check ``urdf``, build its model and store it under ``name`` (default: ``urdf-`` and the
    first 12 hex digits of the content's SHA-256). Uploading the same content twice is harmless.

    Raises:
        InvalidRobotName: ``name`` breaks ``NAME_PATTERN``.
        InvalidURDF: the text is not a usable fixed-base arm (see ``robots.urdf_check``).
        RobotConflict: ``name`` is a catalog robot or holds a different upload.
        UploadStoreFull: the store is at its cap of uploads or bytes.
    """
    digest = hashlib.sha256(urdf.encode()).hexdigest()
    if name is None:
        name = f"urdf-{digest[:12]}"
    check_name(name)
    if is_catalog_robot(name):
        raise RobotConflict(f"name {name!r} belongs to a catalog robot; choose another")
    store = upload_store()
    held = store.digest(name)
    if held is not None and held != digest:
        raise RobotConflict(f"name {name!r} already holds a different URDF; choose another name or delete it first")
    if held == digest:
        robot = load_upload(name)
        if robot is not None:
            return robot
    model = check_urdf(urdf)
    robot = robot_from_model(name, model, "upload", None)
    store.put(name, digest, urdf, robot.dof)
    with _lock:
        _cache.put((name, digest), robot)
    return robot


def delete_upload(name: str) -> None:
    """Remove the upload ``name`` from the store and from this process's cache.

    Raises:
        CatalogRobotReadOnly: ``name`` is a bundled or example-robot-data robot.
        UnknownRobot: no upload has that name.
    """
    if is_catalog_robot(name):
        raise CatalogRobotReadOnly(f"{name!r} is a catalog robot; only uploaded robots can be deleted")
    removed = upload_store().delete(name)
    with _lock:
        _cache.discard(name)
    if not removed:
        raise UnknownRobot(name, catalog_names())


def list_uploads() -> list[StoredUpload]:
    """Every upload in the store, by name."""
    return upload_store().uploads()
