"""The type of a kernel's arguments as numba sees them, without numba: a hashable key that two
argument lists share exactly when numba types them alike (``numba.typeof``): an array by its
dtype (the dtype itself: two record dtypes of other fields differ), dimensions, layout ('C',
'F' or 'A') and whether it is read-only (numba types every array as aligned); a tuple by its
items; a scalar by its numpy type's name (a Python ``float`` is a float64, an ``int`` an int64,
a ``bool`` a boolean). Anything else (a list, None, an array subclass) has no key (``None``):
such a call goes to numba. An array numba cannot type (of objects) has a key no library holds.

The ahead-of-time library was compiled for fixed types and does not check them (an array of
another dtype would be read as if it were of the compiled one), so a call uses it only when the
key of its arguments is one the library was built for.
"""

from __future__ import annotations

from typing import Any

import numpy as np

_INT64 = (-(2**63), 2**63)


def key(args: tuple) -> tuple | None:
    """The key of ``args`` (module docstring), or ``None`` when one of them has none. Called
    before every call of a kernel the library holds, so the common types (arrays, floats, ints,
    bools) take a short way: about 3 us for fifteen arguments."""
    keys: list[Any] = []
    append = keys.append
    for value in args:
        kind = type(value)
        if kind is np.ndarray:
            flags = value.flags
            layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
            append(("array", value.dtype, value.ndim, layout, not flags.writeable))
        elif kind is float:
            append("float64")
        elif kind is bool:
            append("bool")
        else:
            item = _item(value)
            if item is None:
                return None
            append(item)
    return tuple(keys)


def _item(value: Any) -> Any:
    if isinstance(value, np.ndarray):  # a subclass (a matrix, a memmap): numba's own typing
        return None
    if isinstance(value, tuple):
        items = key(tuple(value))
        return None if items is None else ("tuple", items)
    if isinstance(value, bool | np.bool_):
        return "bool"
    if isinstance(value, float):
        return "float64"
    if isinstance(value, int):
        return "int64" if _INT64[0] <= value < _INT64[1] else None
    if isinstance(value, np.number):
        return value.dtype.name
    return None


def as_json(value: Any) -> Any:
    """A key as JSON can hold it: an array's dtype as its string (``'<f8'``)."""
    if isinstance(value, tuple):
        if value and value[0] == "array":
            return ["array", value[1].str, *value[2:]]
        return [as_json(item) for item in value]
    return value


def as_key(value: Any) -> Any:
    """A key read back from JSON (``as_json``) as the hashable key ``key`` gives."""
    if isinstance(value, list):
        if value and value[0] == "array":
            return ("array", np.dtype(value[1]), *value[2:])
        return tuple(as_key(item) for item in value)
    return value
