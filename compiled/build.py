"""The ahead-of-time build (numba's ``pycc``): the kernels a run calls from Python, each for the
argument types of its calls, compiled into one CPython extension module, with the manifest that
``toptraj.compiled.library`` checks before it uses it.

The install runs it on the typical request (``toptraj.service.warmup``), after numba's cache
holds the kernels: about ten seconds on two cores. Each exported function is a one-line Python
wrapper around the kernel's numba dispatcher, so the kernel itself is compiled with its own
options (``error_model="numpy"`` included) and its callees as numba compiles them; the
library's functions and numba's give the same numbers to the bit (``tests/compiled/``), and
release the interpreter lock while they run, as ``nogil=True`` kernels do.

It needs a C compiler (pycc links the module with the platform's): without one, ``BuildFailed``
says so and every kernel keeps running from numba.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import sys
import sysconfig
import tempfile
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

from toptraj.compiled import arguments, library
from toptraj.compiled.kernel import KERNELS, Kernel, forget_library, recording


class BuildFailed(RuntimeError):
    """The library could not be compiled (no C compiler, a kernel pycc cannot export): every
    kernel runs from numba, as without a library."""


def build(run: Callable[[], object]) -> int:
    """Call ``run`` recording its kernels' calls, compile each called kernel for the argument
    types it was called with, and write the library and its manifest (``library.folder()``);
    the number of functions compiled. Raises ``BuildFailed``."""
    with recording() as calls:
        run()
    exports = _exports(calls)
    if not exports:
        raise BuildFailed("the run called no kernel from Python")
    target = library.folder()
    try:
        target.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=target) as scratch:
            built = _compile(exports, Path(scratch))
            digest = library.digest(built)
            name = f"{library.MODULE}-{digest[:16]}{sysconfig.get_config_var('EXT_SUFFIX')}"
            with _locked(target):  # another build's replace, manifest and clean-up wait
                os.replace(built, target / name)
                _write_atomically(library.manifest_path(), json.dumps(_manifest(exports, name, digest), indent=1))
                for old in target.glob(f"{library.MODULE}-*"):
                    if old.name != name:
                        old.unlink(missing_ok=True)
    except OSError as error:  # a folder that cannot be written
        raise BuildFailed(f"cannot write the library into {target}: {error}") from error
    forget_library()
    return len(exports)


def _manifest(exports: dict[str, tuple[Kernel, tuple, object]], name: str, digest: str) -> dict:
    """What ``library.current`` checks (sources, versions, the library file's SHA-256) and the
    exports by kernel and argument key."""
    return {
        "format": library.FORMAT,
        "versions": library.versions(),
        "sources": _sources(),
        "library": name,
        "sha256": digest,
        "exports": [
            {"module": kernel.__module__, "name": kernel.__name__, "symbol": symbol, "arguments": arguments.as_json(key)}
            for symbol, (kernel, key, _) in exports.items()
        ],
    }


@contextlib.contextmanager
def _locked(folder: Path) -> Iterator[None]:
    """An exclusive lock on ``folder``'s lock file for the block (two installs at once each
    write a whole library and its manifest, the later one winning)."""
    import fcntl

    with open(folder / f"{library.MODULE}.lock", "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _exports(calls: list[tuple[Kernel, tuple]]) -> dict[str, tuple[Kernel, tuple, object]]:
    """``symbol -> (kernel, argument key, numba signature)``, one per kernel and argument key."""
    import numba

    seen: set[tuple[int, tuple]] = set()
    exports: dict[str, tuple[Kernel, tuple, object]] = {}
    for kernel, args in calls:
        key = arguments.key(args)
        if key is None or (id(kernel), key) in seen or not _under_package(kernel) or "<locals>" in kernel.__qualname__:
            continue
        seen.add((id(kernel), key))
        try:
            types = tuple(numba.typeof(value) for value in args)
        except ValueError:  # a value numba cannot type (it ran as Python): nothing to export
            continue
        overload = kernel.dispatcher.overloads.get(types)
        if overload is None:
            continue
        exports[f"kernel_{len(exports)}"] = (kernel, key, overload.signature.return_type(*types))
    return exports


def _compile(exports: dict[str, tuple[Kernel, tuple, object]], scratch: Path) -> Path:
    """The extension module of ``exports``, compiled in ``scratch``; its file."""
    output = io.StringIO()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pycc's pending deprecation
            from numba.pycc import CC

            module = CC(library.MODULE)  # raises without a C compiler
        module.output_dir = str(scratch)
        module.verbose = False
        for symbol, (kernel, _, signature) in exports.items():
            module.export(symbol, signature)(_wrapper(kernel, len(signature.args)))  # type: ignore[attr-defined]
        with contextlib.redirect_stdout(output), contextlib.redirect_stderr(output), warnings.catch_warnings(), _releasing_the_lock():
            warnings.simplefilter("ignore")
            module.compile()
    except Exception as error:  # noqa: BLE001 - a compiler's failure, of whatever kind, is a failed build
        said = " ".join(f"{error} {output.getvalue()[-400:]}".split())  # one line, however the compiler wrote it
        raise BuildFailed(f"{type(error).__name__}: {said[:300]}") from error
    built = scratch / f"{library.MODULE}{sysconfig.get_config_var('EXT_SUFFIX')}"
    if not built.is_file():
        raise BuildFailed(f"pycc wrote no {built.name}")
    return built


@contextlib.contextmanager
def _releasing_the_lock() -> Iterator[None]:
    """pycc compiles its exports with numba's default flags, whose CPython wrappers hold the
    interpreter lock through the call; within the block they release it, as ``nogil=True``
    does for numba's own (every kernel is ``nogil``): a long kernel never stalls the server's
    other threads."""
    from numba.pycc import compiler

    original = compiler.Flags

    class Releasing(original):  # type: ignore[misc, valid-type]
        def __init__(self, *args: object, **keywords: object) -> None:
            super().__init__(*args, **keywords)
            self.release_gil = True

    setattr(compiler, "Flags", Releasing)  # noqa: B010 - a module's class, swapped for the block
    try:
        yield
    finally:
        setattr(compiler, "Flags", original)  # noqa: B010


def _wrapper(kernel: Kernel, count: int) -> Callable:
    """``def call(a0, ..., an): return kernel(a0, ..., an)`` (``count`` arguments, as the kernel
    was called) with the kernel's dispatcher: pycc compiles this with its own flags, the kernel
    keeps its options."""
    names = ", ".join(f"a{index}" for index in range(count))
    namespace: dict = {"kernel": kernel.dispatcher}
    exec(f"def call({names}):\n    return kernel({names})\n", namespace)  # noqa: S102 - a fixed template
    return namespace["call"]


def _under_package(kernel: Kernel) -> bool:
    return _relative(kernel.__module__) is not None


def _relative(module: str) -> str | None:
    file = getattr(sys.modules.get(module), "__file__", None)
    if file is None:
        return None
    try:
        return Path(file).relative_to(library.package_root()).as_posix()
    except ValueError:
        return None


def _sources() -> dict[str, str]:
    """SHA-256 of every module of toptraj that defines a kernel, by its path in the package."""
    root = library.package_root()
    paths = sorted({path for path in (_relative(kernel.__module__) for kernel in KERNELS) if path})
    return {path: library.digest(root / path) for path in paths}


def _write_atomically(path: Path, text: str) -> None:
    scratch = path.with_suffix(f".{os.getpid()}.tmp")
    scratch.write_text(text)
    os.replace(scratch, path)

