"""``METHODS``: every ``timing.method`` name it lists gives the method of that name, made once,
whose module is imported only when the name is first asked for."""

from __future__ import annotations

import pytest

from toptraj.planners.timing import METHODS, ClassicalMethod, PhasePlaneMethod, TimingMethod, ToppraMethod


def test_every_name_gives_its_method_once():
    names = list(METHODS)
    assert names == ["phase_plane", "toppra", "cubic", "quintic", "trapezoidal", "cycloidal", "ruckig", "min_cost", "jerk_limited"]
    for name in names:
        method = METHODS[name]
        assert isinstance(method, TimingMethod) and method.name == name
        assert METHODS[name] is method and METHODS.get(name) is method
    assert isinstance(METHODS["phase_plane"], PhasePlaneMethod) and isinstance(METHODS["toppra"], ToppraMethod)
    assert isinstance(METHODS["quintic"], ClassicalMethod) and METHODS["quintic"].boundary_law == "quintic"
    assert len(METHODS) == len(names) and "search" not in METHODS


def test_an_unknown_name_is_none_or_a_key_error():
    assert METHODS.get("bang_bang") is None
    with pytest.raises(KeyError):
        METHODS["bang_bang"]
