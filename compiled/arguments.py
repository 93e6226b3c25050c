"""The type of a kernel's arguments as numba sees them, without numba: a hashable key that two
argument lists share exactly when numba types them alike (``numba.typeof``): an array by its
dtype, dimensions, layout ('C', 'F' or 'A') and whether it is read-only (numba types every
array as aligned); a tuple by its items; a scalar by its numpy type's name (a Python ``float``
is a float64, an ``int`` an int64, a ``bool`` a boolean). Anything else has no key (``None``): such a call goes to numba.

The ahead-of-time library was compiled for fixed types and does not check them (an array of
another dtype would be read as if it were of the compiled one), so a call uses it only when the
key of its arguments is one the library was built for.
"""

from __future__ import annotations

from typing import Any

import numpy as np

_INT64 = (-(2**63), 2**63)


def key(args: tuple) -> tuple | None:
    """The key of ``args`` (module docstring), or ``None`` when one of them has none."""
    keys = []
    for value in args:
        item = _item(value)
        if item is None:
            return None
        keys.append(item)
    return tuple(keys)


def _item(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        flags = value.flags
        layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
        if not value.dtype.isnative or value.dtype.hasobject or value.dtype.fields is not None:
            return None
        return ("array", value.dtype.str, value.ndim, layout, not flags.writeable)
    if isinstance(value, tuple):
        items = tuple(_item(item) for item in value)
        return None if any(item is None for item in items) else ("tuple", items)
    if isinstance(value, bool | np.bool_):
        return "bool"
    if isinstance(value, float):
        return "float64"
    if isinstance(value, int):
        return "int64" if _INT64[0] <= value < _INT64[1] else None
    if isinstance(value, np.number):
        return value.dtype.name
    return None


def as_key(value: Any) -> Any:
    """A key read back from JSON (lists for tuples) as the hashable key ``key`` gives."""
    if isinstance(value, list):
        return tuple(as_key(item) for item in value)
    return value
