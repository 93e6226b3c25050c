"""The argument key (``toptraj.compiled.arguments``) tells two argument lists apart exactly when
numba types them apart: the ahead-of-time library reads arrays as the types it was built for
without checking, so a call may use it only on the same key."""

from __future__ import annotations

import itertools

import numba
import numpy as np

from toptraj.compiled import arguments


class _Subclass(np.ndarray):
    pass


def _samples():
    base = np.arange(24.0).reshape(4, 6)
    readonly = base.copy()
    readonly.flags.writeable = False
    unaligned = np.frombuffer(b"\0" + base.tobytes(), dtype=np.float64, offset=1, count=24).reshape(4, 6)
    return [
        base, base.copy(), base.T, base[:, ::2], np.asfortranarray(base), readonly, unaligned,
        base.astype(np.float32), base.astype(np.int64), base.astype(np.int32), base > 3.0,
        np.arange(5.0), np.arange(5), np.ones((2, 2, 2)), np.ones(3)[::-1],
        1.5, np.float64(1.5), np.float32(1.5), 3, np.int64(3), np.int32(3), True, np.bool_(False),
        (base, base), (base, np.arange(5.0)), (np.arange(5.0), base), (1.5, 2), (base,),
    ]


def test_two_argument_lists_share_a_key_exactly_when_numba_types_them_alike():
    samples = _samples()
    for first, second in itertools.product(samples, repeat=2):
        same_key = arguments.key((first,)) == arguments.key((second,))
        same_type = numba.typeof(first) == numba.typeof(second)
        assert same_key == same_type, (numba.typeof(first), numba.typeof(second))


def test_what_numba_cannot_type_alike_has_no_key():
    assert arguments.key(([1.0, 2.0],)) is None
    assert arguments.key((None,)) is None
    assert arguments.key((2**64,)) is None
    assert arguments.key((np.ones(2).view(_Subclass),)) is None  # numba's own typing decides


def test_record_arrays_of_other_fields_have_other_keys():
    first = np.zeros(2, dtype=[("a", "<f8"), ("b", "<f8")])
    second = np.zeros(2, dtype=[("a", "<i8"), ("b", "<f8")])
    assert first.dtype.itemsize == second.dtype.itemsize
    assert arguments.key((first,)) != arguments.key((second,))


def test_a_key_read_back_from_json_is_the_same_key():
    import json

    key = arguments.key((np.ones((2, 3)), (1.5, np.arange(3)), True, 4, np.ones(2, dtype=bool)))
    assert arguments.as_key(json.loads(json.dumps(arguments.as_json(key)))) == key
