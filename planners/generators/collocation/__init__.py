"""Free-path motions: the path and its timing optimized together from start to goal."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from toptraj.planners.generators.collocation.collocation import optimize_motion
    from toptraj.planners.generators.collocation.motion import CollocationResult, collocation_path

#: The package's names and their modules, imported when a name is first asked for: a module of
#: the collocation read alone (its report, its switching times) does not import the optimizer.
_MODULES = {"optimize_motion": "collocation", "CollocationResult": "motion", "collocation_path": "motion"}


def __getattr__(name: str) -> Any:
    if name in _MODULES:
        return getattr(importlib.import_module(f"{__name__}.{_MODULES[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["CollocationResult", "collocation_path", "optimize_motion"]
