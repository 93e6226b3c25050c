"""numba's disk cache follows every kernel module (``toptraj.compiled.cache``): a kernel that
calls a kernel of another module compiles again when that module changes, where numba alone
keeps loading the machine code it linked in before; and every module that defines a kernel is
one the cache's stamp reads."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

from toptraj.compiled import cache, kernel

CALLEE = """
from toptraj.compiled import njit


@njit(cache=True)
def constant():
    return {value}
"""
CALLER = """
from toptraj.compiled import njit
from stamp_callee import constant


@njit(cache=True)
def twice():
    return 2.0 * constant()
"""
#: Calls the caller in a fresh process, with the cache's package root at argv[1]
#: (``fresh``: the stamp holds the kernel modules' digest; else numba's own locators).
RUN = """
import sys
from pathlib import Path
from toptraj.compiled import cache

root, fresh = Path(sys.argv[1]), sys.argv[2] == "fresh"
cache.package_root = lambda: root
if not fresh:
    cache.keep_fresh = lambda: None
sys.path.insert(0, str(root / "planners"))
from stamp_caller import twice
print(twice())
"""


def _twice(root: Path, mode: str) -> float:
    environment = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}  # beside the sources
    done = subprocess.run([sys.executable, "-c", RUN, str(root), mode], capture_output=True, text=True, env=environment, check=True)
    return float(done.stdout.split()[-1])


def _package(tmp_path: Path, value: float) -> Path:
    folder = tmp_path / "planners"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "stamp_callee.py").write_text(textwrap.dedent(CALLEE.format(value=value)))
    (folder / "stamp_caller.py").write_text(textwrap.dedent(CALLER))
    return tmp_path


def test_a_kernel_compiles_again_when_a_kernel_it_calls_changes(tmp_path):
    root = _package(tmp_path, 1.5)
    assert _twice(root, "fresh") == 3.0  # compiled and cached
    assert _twice(root, "fresh") == 3.0  # loaded from the cache
    _package(tmp_path, 4.0)  # the callee's module edited, the caller's not
    assert _twice(root, "fresh") == 8.0


def test_numba_alone_keeps_the_stale_machine_code(tmp_path):
    """What the stamp prevents: numba keys the caller to its own module's source only."""
    root = _package(tmp_path, 1.5)
    assert _twice(root, "numba") == 3.0
    _package(tmp_path, 4.0)
    assert _twice(root, "numba") == 3.0  # the callee's old constant, linked into the cached caller


def test_every_kernel_module_is_in_the_stamp():
    import toptraj.planners.generators.search.simplex_kernels  # noqa: F401  (kernels calling other modules' kernels)
    import toptraj.service.warmup  # noqa: F401  (imports the typical request's kernel modules)

    sources = {path.resolve() for path in cache.kernel_sources()}
    defining = {Path(sys.modules[k.__module__].__file__).resolve() for k in kernel.KERNELS}
    assert defining and defining <= sources
    assert all(cache.is_kernel_module(str(path)) for path in defining)
    assert not cache.is_kernel_module(cache.__file__)
