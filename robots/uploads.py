"""Uploaded URDFs: checked at upload (``toptraj.robots.urdf_check``), kept durably in an ``UploadStore``
(``toptraj.robots.store``), and built into ``Robot`` objects on demand, of which a bounded LRU cache keeps
the most recently used. However many uploads the store holds, a process keeps at most
``cache_size`` upload models in memory.

Every lookup asks the store which text a name holds, so an upload, replacement or deletion made
by another process (or before a restart) is seen at once; the cache is keyed by name and digest
and never serves a text the store no longer holds under that name.

The process's store is set by ``configure_uploads`` (the service does it from its settings);
until then it is ``UploadStore(default_data_dir())`` with the default caps.
"""

from __future__ import annotations

import dataclasses
import hashlib
import re
import threading
from collections import OrderedDict
from pathlib import Path

import pinocchio as pin

from toptraj.robots.catalog import catalog_names, is_catalog_robot, robot_from_model
from toptraj.robots.equipment import InvalidEquipment, equip
from toptraj.robots.errors import (
    CatalogRobotReadOnly,
    InvalidLimits,
    InvalidRobotName,
    InvalidURDF,
    RobotConflict,
    UnknownRobot,
    excerpt,
)
from toptraj.robots.robot import Robot
from toptraj.robots.srdf import check_links
from toptraj.robots.store import DEFAULT_MAX_BYTES, DEFAULT_MAX_UPLOADS, StoredUpload, UploadStore, default_data_dir
from toptraj.robots.upload_options import InvalidUpload, UploadOptions, apply_locks, yaml_limit_arrays
from toptraj.robots.urdf_check import check_urdf, mesh_count
from toptraj.robots.urdf_tree import mimic_joints

DEFAULT_CACHE_SIZE = 32
MAX_NAME_CHARS = 64
#: A name starts with a letter and holds at most 64 letters, digits, '_', '.' or '-'.
NAME_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_.-]{0,63}")


class _RobotCache:
    """Least-recently-used ``Robot`` objects keyed by ``(name, (digest, options))``, at most ``size``."""

    def __init__(self, size: int):
        self.size = size
        self._robots: OrderedDict[tuple[str, tuple[str, str]], Robot] = OrderedDict()

    def get(self, key: tuple[str, tuple[str, str]]) -> Robot | None:
        robot = self._robots.get(key)
        if robot is not None:
            self._robots.move_to_end(key)
        return robot

    def put(self, key: tuple[str, tuple[str, str]], robot: Robot) -> None:
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


def build_upload(name: str, urdf: str, options: UploadOptions) -> Robot:
    """The robot of an upload: its URDF checked and built, the locked joints fixed, the limits
    of its joint_limits.yaml applied, and notes on what was not used.

    Raises:
        InvalidURDF: the text is not a usable fixed-base arm.
        InvalidUpload: the options do not fit the URDF.
        InvalidEquipment: the default payload's frame is not a frame of the robot.
        InvalidLimits: a limit outside the accepted range of its kind (``toptraj.robots.ranges``).
    """
    full = check_urdf(urdf)
    model = apply_locks(full, options.locked_joints)
    given = yaml_limit_arrays(tuple(model.names[1:]), options) if options.joint_limits else None
    notes = list(options.notes)
    meshes = mesh_count(urdf)
    if meshes:
        notes.append(
            f"the URDF's {meshes} mesh files are not loaded: the dynamics come from its <inertial> elements, "
            "and obstacle checks use a capsule of 0.03 m radius along each link"
        )
    for joint, mimicked, multiplier, offset in mimic_joints(urdf):
        if joint not in options.locked_joints:
            notes.append(
                f"joint {excerpt(joint)} mimics joint {excerpt(mimicked)} in the URDF (its position {multiplier:g} times "
                f"that joint's plus {offset:g}), which is not modelled: it is planned as a joint of its own, with its "
                "own limits and torque; give waypoints that keep the coupling, or lock it (locked_joints) where it does not move"
            )
    if options.locked_joints:
        notes.append("joints locked: " + ", ".join(f"{joint} = {value:g}" for joint, value in options.locked_joints.items()))
    if options.allowed_collisions:
        check_links(options.allowed_collisions, [frame.name for frame in model.frames if frame.type == pin.FrameType.BODY])
    robot = robot_from_model(name, model, "upload", None, given, options.locked_joints, tuple(notes))
    if options.allowed_collisions:
        robot = dataclasses.replace(robot, allowed_collisions=frozenset(options.allowed_collisions))
    return robot if options.payload is None else equip(robot, options.payload)


def _build(name: str, key: tuple[str, str], urdf: str) -> Robot:
    robot = build_upload(name, urdf, UploadOptions.from_json(key[1]))
    with _lock:
        _cache.put((name, key), robot)
    return robot


def load_upload(name: str) -> Robot | None:
    """The uploaded robot ``name``, built from the store unless cached; ``None`` if the store
    holds no such name.

    Raises:
        InvalidURDF: the stored text no longer passes the checks (they became stricter).
    """
    store = upload_store()
    key = store.key(name)
    if key is None:
        return None
    with _lock:
        robot = _cache.get((name, key))
    if robot is not None:
        return robot
    stored = store.read(name)
    if stored is None:
        return None
    digest, urdf, options = stored
    try:
        return _build(name, (digest, options), urdf)
    except (InvalidURDF, InvalidUpload, InvalidLimits, InvalidEquipment) as error:
        raise InvalidURDF(f"the stored upload {excerpt(name)} no longer passes the checks: {error.detail}") from None


def register_urdf(urdf: str, name: str | None = None, options: UploadOptions | None = None) -> Robot:
    """Check ``urdf`` and its ``options``, build its model and store both under ``name``
    (default: ``urdf-`` and the first 12 hex digits of the SHA-256 of the content and the
    options). Uploading the same content with the same options twice is harmless.

    Raises:
        InvalidRobotName: ``name`` breaks ``NAME_PATTERN``.
        InvalidURDF: the text is not a usable fixed-base arm (see ``toptraj.robots.urdf_check``).
        InvalidUpload: the options do not fit the URDF (``toptraj.robots.upload_options``).
        InvalidLimits: a limit outside the accepted range of its kind (``toptraj.robots.ranges``).
        RobotConflict: ``name`` is a catalog robot or holds a different upload.
        UploadStoreFull: the store is at its cap of uploads or bytes.
    """
    options = options or UploadOptions()
    stored_options = options.to_json()
    digest = hashlib.sha256(urdf.encode()).hexdigest()
    if name is None:
        named = digest if not stored_options else hashlib.sha256((urdf + stored_options).encode()).hexdigest()
        name = f"urdf-{named[:12]}"
    check_name(name)
    if is_catalog_robot(name):
        raise RobotConflict(f"name {name!r} belongs to a catalog robot; choose another")
    alike = next((known for known in catalog_names() if known.lower() == name.lower()), None)
    if alike is not None:  # a request naming one, mistyped in case, would plan the other
        raise RobotConflict(f"name {name!r} differs from the catalog robot {alike!r} only in case; choose another")
    store = upload_store()
    held = store.key(name)
    alike = None if held is not None else store.alike(name)
    if alike is not None:  # refused before the model is built; ``put`` refuses it too, atomically
        raise RobotConflict(f"name {name!r} differs from the upload {alike!r} only in case; choose another")
    if held is not None and held[0] != digest:
        raise RobotConflict(f"name {name!r} already holds a different URDF; choose another name or delete it first")
    if held is not None and held[1] != stored_options:
        raise RobotConflict(
            f"name {name!r} already holds this URDF with other options (locked joints, joint limits); choose "
            "another name or delete it first"
        )
    if held is not None:
        robot = load_upload(name)
        if robot is not None:
            return robot
    robot = build_upload(name, urdf, options)
    store.put(name, digest, urdf, robot.dof, stored_options)
    with _lock:
        _cache.put((name, (digest, stored_options)), robot)
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
