"""The library of kernels compiled ahead of time (``toptraj.compiled.build``): a CPython extension
module and the manifest that describes it, beside numba's cache (``NUMBA_CACHE_DIR``, else this
package's ``__pycache__``).

The manifest names the library's file and, for each compiled function, its kernel (module and
name) and the argument key it was built for (``toptraj.compiled.arguments``). It also holds what
the library was compiled from: the SHA-256 of every module that defines a kernel, numba's and
numpy's versions, Python's. The library is used only while all of them still hold, so an edited
kernel, or another numba, runs from numba again until the next build; a missing, partial or
unreadable library is the same as none (``functions_of`` gives ``{}``): the library file's own
SHA-256 is checked before it is loaded, since loading maps it.

Loaded once per process, at the first call of any kernel (a few milliseconds: the manifest, the
hashes of some twenty modules and of the library file, one ``dlopen``).
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import json
import os
import sys
import threading
from pathlib import Path
from typing import Any

from toptraj.compiled.arguments import as_key

#: The manifest's format; a manifest of another is ignored.
FORMAT = 2
#: The extension module's name (its ``PyInit_`` symbol); its file is named by its own hash.
MODULE = "toptraj_kernels"

_lock = threading.Lock()
_table: dict[tuple[str, str], dict] | None = None


def folder() -> Path:
    """Where the library and its manifest live: ``$TOPTRAJ_KERNEL_LIBRARY`` when set, else
    under ``$NUMBA_CACHE_DIR`` when numba's cache is elsewhere than beside the sources (a folder
    per installed package, as numba keys its cache by source path: two checkouts sharing the
    cache keep a library each), else this package's ``__pycache__``."""
    chosen = os.environ.get("TOPTRAJ_KERNEL_LIBRARY")
    if chosen:
        return Path(chosen)
    cache = os.environ.get("NUMBA_CACHE_DIR")
    if not cache:
        return Path(__file__).resolve().parent / "__pycache__"
    root = hashlib.sha256(str(package_root().resolve()).encode()).hexdigest()[:16]
    return Path(cache) / f"toptraj-{root}"


def manifest_path() -> Path:
    """The manifest's file (``folder()``)."""
    return folder() / f"{MODULE}.json"


def package_root() -> Path:
    """The ``toptraj`` package's folder, which the manifest's source paths are relative to."""
    import toptraj

    return Path(toptraj.__file__).parent


def in_use() -> bool:
    """Whether kernels may run from the library: ``TOPTRAJ_KERNELS=library``, which the one-shot
    commands (``toptraj plan``, ``compare``, ``plot``) set unless it is set, and not
    ``NUMBA_DISABLE_JIT=1`` (numba then runs every kernel as Python). A long-lived process (a
    server) keeps numba's dispatchers: it gains nothing from sparing numba's start once, and a
    call through the library costs about 3 us more (its argument check, about 0.15 ms of the
    typical request's 60 calls)."""
    chosen = os.environ.get("TOPTRAJ_KERNELS", "").lower() == "library"
    return chosen and os.environ.get("NUMBA_DISABLE_JIT", "0") in ("", "0")


def digest(path: Path) -> str:
    """SHA-256 of a file's bytes, in hex."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def versions() -> dict[str, str]:
    """What the library depends on besides the kernels' sources: Python's version, numpy's, and
    numba's (read from its files: importing numba is what the library spares)."""
    import numpy

    spec = importlib.util.find_spec("numba")
    numba_file = Path(spec.origin).parent / "_version.py" if spec and spec.origin else None
    numba = digest(numba_file) if numba_file and numba_file.is_file() else "absent"
    return {"python": sys.version, "numpy": numpy.__version__, "numba": numba}


def functions_of(module: str, name: str) -> dict:
    """The library's functions of the kernel ``module.name``, by argument key; ``{}`` when the
    library lacks it, is stale or absent, or is not ``in_use()``."""
    global _table
    if _table is None:
        with _lock:
            if _table is None:
                _table = _load(manifest_path()) if in_use() else {}
    return _table.get((module, name), {})


def forget() -> None:
    """The next ``functions_of`` reads the manifest again."""
    global _table
    with _lock:
        _table = None


def current(manifest: dict[str, Any]) -> bool:
    """Whether ``manifest`` describes a library built from the sources and versions of now."""
    if manifest.get("format") != FORMAT or manifest.get("versions") != versions():
        return False
    root = package_root()
    try:
        return all(digest(root / path) == sha for path, sha in manifest["sources"].items())
    except OSError:
        return False


def _load(path: Path) -> dict[tuple[str, str], dict]:
    try:
        manifest = json.loads(path.read_text())
        if not current(manifest):
            return {}
        location = path.parent / manifest["library"]
        if digest(location) != manifest["sha256"]:  # a truncated or altered file is never mapped
            return {}
        loader = importlib.machinery.ExtensionFileLoader(MODULE, str(location))
        spec = importlib.util.spec_from_file_location(MODULE, location, loader=loader)
        if spec is None:
            return {}
        module = importlib.util.module_from_spec(spec)
        loader.exec_module(module)
        table: dict[tuple[str, str], dict] = {}
        for export in manifest["exports"]:
            function = getattr(module, export["symbol"])
            table.setdefault((export["module"], export["name"]), {})[as_key(export["arguments"])] = function
        return table
    except (OSError, ValueError, KeyError, TypeError, ImportError, AttributeError):
        return {}
