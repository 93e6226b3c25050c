"""numba's disk cache of the kernels, kept fresh across modules.

numba keys a cached kernel to its own module's source (its SHA-256): a kernel that calls kernels
of other modules holds their machine code too, linked in when it was compiled, and numba keeps
loading it after those modules change. An edited distance kernel then ran in the search's
Nelder-Mead loop as it was before the edit (measured: the old, slower objective, 0.85 ms an
evaluation on ur5 instead of 0.66 ms; an edit that changed an answer would have been served
with the old answer until the cache was cleared).

``KernelLocator`` is numba's own locator (the same folder, the same file names) with a source
stamp that also holds the SHA-256 of every kernel module of the package (``kernel_sources``:
the modules that import this package's ``njit``), so that an edit to any of them makes every
kernel compile again at its next use, as the install's warm-up does. It serves the kernel
modules only; every other function numba caches is located as before (and
``NUMBA_CACHE_LOCATOR_CLASSES``, when set, replaces numba's locators, this one with them).

A process whose kernel modules changed on disk after it imported them (code updated under a
running server, or edited during a test run) compiles its kernels without caching them
(``current``), so that no code older than the files is saved under their stamp.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
from pathlib import Path
from typing import Any

from toptraj.compiled.library import package_root

#: What marks a module that defines kernels: it imports this package's ``njit`` (alone or with
#: other names, in parentheses or not, from ``toptraj.compiled`` or ``toptraj.compiled.kernel``).
KERNEL_IMPORT = re.compile(rb"^[ \t]*from[ \t]+toptraj\.compiled(?:\.kernel)?[ \t]+import[ \t]+(?:\([^)]*\bnjit\b|[^\n#]*\bnjit\b)", re.M)
#: (st_mtime_ns, st_size) of each module that defined a kernel in this process, when it did.
_imported: dict[str, tuple[int, int]] = {}
#: The subpackages that may define kernels (the layers above ``compiled``).
KERNEL_PACKAGES = ("robots", "planners")


def kernel_sources() -> list[Path]:
    """Every module of ``KERNEL_PACKAGES`` that imports this package's ``njit``, in a fixed order
    (symbolic links followed, as the package's own folders are links)."""
    found = []
    for package in KERNEL_PACKAGES:
        for folder, folders, files in os.walk(package_root() / package, followlinks=True):
            folders[:] = sorted(name for name in folders if name != "__pycache__")
            for name in sorted(files):
                path = Path(folder) / name
                if name.endswith(".py") and KERNEL_IMPORT.search(path.read_bytes()):
                    found.append(path)
    return found


@functools.cache
def _sources() -> tuple[str, frozenset[Path]]:
    """SHA-256 (hex) of the kernel modules' paths (relative to the package) and bytes, and
    their files (symbolic links resolved); read once per process (a few milliseconds)."""
    root, digest = package_root(), hashlib.sha256()
    paths = kernel_sources()
    for path in paths:
        digest.update(str(path.relative_to(root)).encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest(), frozenset(path.resolve() for path in paths)


def sources_digest() -> str:
    """SHA-256 (hex) of every kernel module's path and bytes."""
    return _sources()[0]


def defined_in(py_file: str) -> None:
    """Note that a kernel was defined from ``py_file`` now (its module is being imported): the
    file's state then is that of the code this process runs (``current``)."""
    if py_file not in _imported:
        try:
            stat = os.stat(py_file)
        except OSError:
            return
        _imported[py_file] = (stat.st_mtime_ns, stat.st_size)


def current() -> bool:
    """Whether every module that defined a kernel in this process is still, on disk, the file it
    imported. Else its kernels must not be cached: this process would save the code it imported
    under the stamp of the files now on disk (``sources_digest``), and every later process would
    load that old code as fresh."""
    for py_file, state in list(_imported.items()):
        try:
            stat = os.stat(py_file)
        except OSError:
            return False
        if (stat.st_mtime_ns, stat.st_size) != state:
            return False
    return True


def is_kernel_module(py_file: str) -> bool:
    """Whether ``py_file`` is one of the kernel modules (``kernel_sources``)."""
    try:
        return Path(py_file).resolve() in _sources()[1]
    except OSError:
        return False


def locator_class() -> type:
    """``KernelLocator``, made on first need (numba imported)."""
    from numba.core import caching

    class KernelLocator(caching._CacheLocator):
        """numba's locator for a kernel of toptraj (``inner``) with ``sources_digest`` in its stamp."""

        def __init__(self, inner: Any) -> None:
            self._inner = inner

        def ensure_cache_path(self) -> None:
            self._inner.ensure_cache_path()

        def get_cache_path(self) -> str:
            return self._inner.get_cache_path()

        def get_source_stamp(self) -> Any:
            return (self._inner.get_source_stamp(), sources_digest())

        def get_disambiguator(self) -> str:
            return self._inner.get_disambiguator()

        @classmethod
        def from_function(cls, py_func: Any, py_file: str) -> Any:
            if not is_kernel_module(py_file):
                return None
            classes: list[Any] = caching.CacheImpl._locator_classes
            for base in classes:
                if base is not cls:
                    inner = base.from_function(py_func, py_file)
                    if inner is not None:
                        return cls(inner)
            return None

    return KernelLocator


def keep_fresh() -> None:
    """Put ``KernelLocator`` first among numba's cache locators (once; numba imported)."""
    from numba.core import caching

    classes: list[Any] = caching.CacheImpl._locator_classes
    if not any(getattr(cls, "__name__", "") == "KernelLocator" for cls in classes):
        classes.insert(0, locator_class())
