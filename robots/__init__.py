"""Robots: the catalog (bundled paper arms, example-robot-data arms), uploads and ``Robot``."""

from robots.catalog import catalog_names
from robots.errors import (
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
from robots.limits import LIMIT_KINDS, JointLimits, ToolSpeedLimit
from robots.registry import load
from robots.robot import Robot
from robots.store import StoredUpload, UploadStore, default_data_dir
from robots.uploads import configure_uploads, delete_upload, list_uploads, register_urdf, upload_store

__all__ = [
    "LIMIT_KINDS",
    "CatalogRobotReadOnly",
    "InvalidLimits",
    "InvalidRobotName",
    "InvalidURDF",
    "JointLimits",
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
    "list_uploads",
    "load",
    "register_urdf",
    "upload_store",
]
