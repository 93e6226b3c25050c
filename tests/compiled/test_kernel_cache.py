"""numba's disk cache follows every kernel module (``toptraj.compiled.cache``): a kernel that
calls a kernel of another module compiles again when that module changes, where numba alone
keeps loading the machine code it linked in before; and every module that defines a kernel is
one the cache's stamp reads."""

from __future__ import annotations

import importlib
import os
import pkgutil
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
#: (``fresh``: the stamp holds the kernel modules' digest; else numba's own locators); with
#: argv[3] and argv[4], writes that text to that module's file after the import, before the call.
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
if len(sys.argv) > 3:
    (root / "planners" / sys.argv[3]).write_text(sys.argv[4])
print(twice())
"""


def _twice(root: Path, mode: str, edit: tuple[str, str] = ()) -> float:
    environment = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}  # beside the sources
    done = subprocess.run([sys.executable, "-c", RUN, str(root), mode, *edit], capture_output=True, text=True, env=environment, check=True)
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


def test_a_process_whose_modules_changed_after_its_import_caches_nothing(tmp_path):
    """The first process runs the code it imported (the callee's 1.5, then the caller's 2 x)
    and must not save it under the stamp of the edited files: the next process runs them."""
    root = _package(tmp_path, 1.5)
    assert _twice(root, "fresh", ("stamp_callee.py", textwrap.dedent(CALLEE.format(value=4.0)))) == 3.0
    assert _twice(root, "fresh") == 8.0
    thrice = textwrap.dedent(CALLER).replace("2.0 * constant()", "3.0 * constant()")
    assert _twice(root, "fresh", ("stamp_caller.py", thrice)) == 8.0
    assert _twice(root, "fresh") == 12.0


def test_kernel_modules_are_told_by_any_form_of_the_import():
    found = [bool(cache.KERNEL_IMPORT.search(text)) for text in (
        b"from toptraj.compiled import njit",
        b"from toptraj.compiled import arguments, njit",
        b"from toptraj.compiled.kernel import njit",
        b"from toptraj.compiled import (\n    arguments,\n    njit,\n)",
        b"    from toptraj.compiled import njit  # in a function",
        b"from toptraj.compiled import arguments\nfrom toptraj.compiled.build import build",
        b"# from toptraj.compiled import njit\n",
    )]
    assert found == [True, True, True, True, True, False, False]


def test_every_kernel_module_is_in_the_stamp():
    import toptraj.planners
    import toptraj.robots

    for package in (toptraj.robots, toptraj.planners):  # every module (the warm-ups, which plan, aside)
        for module in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if not module.name.endswith(".warm"):
                importlib.import_module(module.name)
    sources = {path.resolve() for path in cache.kernel_sources()}
    defining = {Path(sys.modules[k.__module__].__file__).resolve() for k in kernel.KERNELS}
    assert defining and defining <= sources
    assert all(cache.is_kernel_module(str(path)) for path in defining)
    assert not cache.is_kernel_module(cache.__file__)
