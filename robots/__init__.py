"""Robots: the catalog (bundled paper arms, example-robot-data arms), uploads and ``Robot``.

The uploads and their store (SQLite, YAML joint limits) are imported when first named: a catalog
robot needs neither (``toptraj plan`` of a ur5 request spares their imports).
"""

from typing import TYPE_CHECKING, Any

from toptraj.robots.catalog import catalog_names
from toptraj.robots.equipment import InvalidEquipment, Mounting, Payload, equip
from toptraj.robots.errors import (
    CatalogRobotReadOnly,
    InvalidLimits,
    InvalidRobotName,
    InvalidURDF,
    RobotConflict,
    ToptrajError,
    UnknownRobot,
    UploadStoreFull,
    UploadStoreUnavailable,
)
from toptraj.robots.limits import LIMIT_KINDS, JointLimits, LimitZone, ToolSpeedLimit
from toptraj.robots.registry import load
from toptraj.robots.robot import Robot

if TYPE_CHECKING:
    from toptraj.robots.store import StoredUpload, UploadStore, default_data_dir
    from toptraj.robots.uploads import configure_uploads, delete_upload, list_uploads, register_urdf, upload_store

#: The names imported when first asked for, by module.
_LAZY = {
    "toptraj.robots.store": ("StoredUpload", "UploadStore", "default_data_dir"),
    "toptraj.robots.uploads": ("configure_uploads", "delete_upload", "list_uploads", "register_urdf", "upload_store"),
}


def __getattr__(name: str) -> Any:
    import importlib

    for module, names in _LAZY.items():
        if name in names:
            return getattr(importlib.import_module(module), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "LIMIT_KINDS",
    "CatalogRobotReadOnly",
    "InvalidEquipment",
    "InvalidLimits",
    "InvalidRobotName",
    "InvalidURDF",
    "JointLimits",
    "LimitZone",
    "Mounting",
    "Payload",
    "ToolSpeedLimit",
    "Robot",
    "RobotConflict",
    "StoredUpload",
    "ToptrajError",
    "UnknownRobot",
    "UploadStore",
    "UploadStoreFull",
    "UploadStoreUnavailable",
    "catalog_names",
    "configure_uploads",
    "default_data_dir",
    "delete_upload",
    "equip",
    "list_uploads",
    "load",
    "register_urdf",
    "upload_store",
]
