"""Robots: the catalog (bundled paper arms, example-robot-data arms), uploads and ``Robot``."""

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
from toptraj.robots.store import StoredUpload, UploadStore, default_data_dir
from toptraj.robots.uploads import configure_uploads, delete_upload, list_uploads, register_urdf, upload_store

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
