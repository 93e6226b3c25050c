"""Timing methods: each reads ``PathConstraints`` and returns a ``TimeScaling``.

``METHODS`` names every method and imports each one's module when it is first asked for, so
that a request imports the method it names and not the others (ruckig, min_cost's process
pool, jerk_limited's sparse programs): ``toptraj plan`` of a phase_plane request starts faster.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

from toptraj.planners.timing.base import TimeScaling, TimingMethod

if TYPE_CHECKING:
    from toptraj.planners.timing.laws.method import ClassicalMethod
    from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
    from toptraj.planners.timing.toppra_method import ToppraMethod

_LAWS = "toptraj.planners.timing.laws.method"
#: ``timing.method`` name -> the module of its method and the function of that module that
#: makes it (called once, without arguments).
_WHERE: dict[str, tuple[str, str]] = {
    "phase_plane": ("toptraj.planners.timing.phase_plane.method", "PhasePlaneMethod"),
    "toppra": ("toptraj.planners.timing.toppra_method", "ToppraMethod"),
    "cubic": (_LAWS, "classical_methods"),
    "quintic": (_LAWS, "classical_methods"),
    "trapezoidal": (_LAWS, "classical_methods"),
    "cycloidal": (_LAWS, "classical_methods"),
    "ruckig": ("toptraj.planners.timing.ruckig_method", "RuckigMethod"),
    "min_cost": ("toptraj.planners.timing.min_cost", "MinCostMethod"),
    "jerk_limited": ("toptraj.planners.timing.jerk.method", "JerkLimitedMethod"),
}
#: The classes this package names, from the modules of ``_WHERE``.
_CLASSES = {"PhasePlaneMethod": _WHERE["phase_plane"][0], "ToppraMethod": _WHERE["toppra"][0], "ClassicalMethod": _LAWS}


class _Methods(Mapping[str, TimingMethod]):
    """``timing.method`` name -> its method (one instance per name, made when first asked for)."""

    def __init__(self) -> None:
        self._made: dict[str, TimingMethod] = {}

    def __getitem__(self, name: str) -> TimingMethod:
        if name not in self._made:
            module, maker = _WHERE[name]
            made = getattr(importlib.import_module(module), maker)()
            for method in made if isinstance(made, list) else [made]:
                self._made.setdefault(method.name, method)
        return self._made[name]

    def __iter__(self) -> Iterator[str]:
        return iter(_WHERE)

    def __len__(self) -> int:
        return len(_WHERE)


#: ``timing.method`` name -> method.
METHODS: Mapping[str, TimingMethod] = _Methods()


def __getattr__(name: str) -> Any:
    """``ClassicalMethod``, ``PhasePlaneMethod`` and ``ToppraMethod``, imported when asked for."""
    if name in _CLASSES:
        return getattr(importlib.import_module(_CLASSES[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["METHODS", "ClassicalMethod", "PhasePlaneMethod", "TimeScaling", "TimingMethod", "ToppraMethod"]
