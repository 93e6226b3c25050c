"""The rules between the fields of a compare body (``CompareRequest``): a comparison runs the
methods of its ``methods``, each once; a ``timing.method`` outside them would be dropped
without a word, so it is refused naming both and the fix."""

from __future__ import annotations

from typing import Any


def each_method_once(cls: type, methods: list[str]) -> list[str]:
    """``methods``, once none is listed twice (it would be computed twice for one answer)."""
    twice = [method for index, method in enumerate(methods) if method in methods[:index]]
    if twice:
        raise ValueError(f"{twice[0]!r} is listed twice; list each method once: {list(dict.fromkeys(methods))}")
    return methods


def timing_method_among_methods(request: Any) -> Any:
    """``request`` (a ``CompareRequest``), once a ``timing.method`` it gives is among its ``methods``."""
    method = request.timing.method
    if "method" in request.timing.model_fields_set and method not in request.methods:
        raise ValueError(
            f"timing.method {method!r} conflicts with methods {request.methods}: a comparison runs the methods of "
            f"`methods`; add {method!r} to methods, or leave timing.method out"
        )
    return request
