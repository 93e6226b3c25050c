"""Compiled kernels: numba's ``njit`` with its options, made where a kernel is first called.

A kernel is a Python function over numpy arrays and scalars (``@njit(cache=True, nogil=True)``
on its definition, as with numba). It runs, in this order of preference:

* in a process that answers one request and ends (``toptraj plan``, ``compare`` and ``plot`` set
  ``TOPTRAJ_KERNELS=library``), from the library compiled ahead of time at the install
  (``toptraj.compiled.build``, loaded by ``toptraj.compiled.library``): the typical request's
  kernels, for the argument types they were built for. Loading it takes a few milliseconds and
  needs neither numba nor LLVM, so ``toptraj plan`` of the typical request never imports numba
  (its import and first cache load cost most of a second);
* else numba's just-in-time compilation, loaded from numba's cache (``cache=True``), imported
  only then: in a server always (its start is paid once; a call through the library costs
  about 3 us more than through numba's dispatcher, its argument check).

Both compile the same source with the same options through the same LLVM, so they give the same
numbers to the bit (``tests/compiled/``).

    from toptraj.compiled import njit

    @njit(cache=True, nogil=True)
    def kernel(values: np.ndarray) -> float: ...
"""

from __future__ import annotations

from toptraj.compiled.kernel import Kernel, njit

__all__ = ["Kernel", "njit"]
