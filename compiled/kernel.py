"""One compiled kernel (``Kernel``) and its decorator (``njit``): a Python function that runs
from the library compiled ahead of time where that library holds it for the arguments given,
else from numba's just-in-time dispatcher, made (and numba imported) on first need.

Inside other kernels a ``Kernel`` is its numba dispatcher: numba types a ``Kernel`` global as
``types.Dispatcher(kernel.dispatcher)`` (``_teach_numba``), so one kernel calls another, and
``inline="always"`` inlines it, exactly as with numba's own ``njit``.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from typing import Any

from toptraj.compiled import arguments, cache, library

#: Every kernel made so far, in the order their modules defined them.
KERNELS: list[Kernel] = []
_numba_lock = threading.RLock()
_numba_taught = False
#: While set (``recording``), each call from Python appends ``(kernel, args)`` to it.
_recorder: list[tuple[Kernel, tuple]] | None = None


class Kernel:
    """A Python function compiled by numba with ``options`` (those of ``numba.njit``), called
    through the ahead-of-time library when it holds the function for the arguments' types."""

    def __init__(self, function: Callable, options: dict[str, Any]) -> None:
        self.py_func = function
        self.options = dict(options)
        self.__name__ = function.__name__
        self.__qualname__ = function.__qualname__
        self.__module__ = function.__module__
        self.__doc__ = function.__doc__
        self.__wrapped__ = function
        self._dispatcher: Any = None
        self._ahead: dict | None = None  # argument key -> compiled function; {} when none

    @property
    def dispatcher(self) -> Any:
        """numba's dispatcher of the function (numba imported and taught ``Kernel`` first)."""
        if self._dispatcher is None:
            with _numba_lock:
                if self._dispatcher is None:
                    try:
                        _teach_numba()
                        import numba

                        options = self.options
                        if options.get("cache") and not cache.current():  # code older than its files: not saved
                            options = {**options, "cache": False}
                        self._dispatcher = numba.njit(**options)(self.py_func)
                    except Exception as error:  # not an AttributeError, which __getattr__ would hide
                        raise RuntimeError(f"numba's dispatcher of {self!r} could not be made: {error!r}") from error
        return self._dispatcher

    def __call__(self, *args: Any, **keywords: Any) -> Any:
        if keywords:
            return self.dispatcher(*args, **keywords)
        if _recorder is not None:  # a build records what numba compiles, never the library's
            _recorder.append((self, args))
            return self.dispatcher(*args)
        ahead = self._ahead
        if ahead is None:
            ahead = self._ahead = library.functions_of(self.__module__, self.__name__)
        if ahead:
            function = ahead.get(arguments.key(args))
            if function is not None:
                return function(*args)
        return self.dispatcher(*args)

    def loaded(self) -> int:
        """How many argument types this kernel runs for now without compiling or loading
        anything: those of the library it has looked up, and those numba's dispatcher holds."""
        held = len(self._ahead or {})
        return held + len(getattr(self._dispatcher, "signatures", ()))  # NUMBA_DISABLE_JIT: a function

    def __getattr__(self, name: str) -> Any:
        # numba's own attributes (signatures, targetoptions, overloads, ...), from the dispatcher.
        # (``dispatcher`` too: an AttributeError raised while making it is not looked up again)
        if name.startswith("__") or name in ("_dispatcher", "_ahead", "py_func", "options", "dispatcher"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __reduce__(self) -> str:
        # pickled by reference, as a module-level function (its module's attribute)
        return self.__qualname__

    def __repr__(self) -> str:
        return f"<kernel {self.__module__}.{self.__qualname__}>"


def njit(function: Callable | None = None, **options: Any) -> Any:
    """``@njit(cache=True, nogil=True, ...)`` (or ``@njit``): ``function`` as a ``Kernel``
    compiled with numba's ``njit`` options. With ``NUMBA_DISABLE_JIT=1`` the kernels run as
    Python, as numba's own do."""

    def make(function: Callable) -> Kernel:
        cache.defined_in(function.__code__.co_filename)
        kernel = Kernel(function, options)
        KERNELS.append(kernel)
        return kernel

    return make(function) if function is not None else make


@contextlib.contextmanager
def recording() -> Iterator[list[tuple[Kernel, tuple]]]:
    """Within the block, every kernel runs from numba and each call from Python is recorded
    (``calls``: ``(kernel, args)``), for the ahead-of-time build."""
    global _recorder
    calls: list[tuple[Kernel, tuple]] = []
    _recorder = calls
    try:
        yield calls
    finally:
        _recorder = None


def forget_library() -> None:
    """Every kernel looks the ahead-of-time library up again at its next call (after a build,
    or after ``TOPTRAJ_KERNELS`` changed)."""
    library.forget()
    for kernel in KERNELS:
        kernel._ahead = None


def _teach_numba() -> None:
    """numba types a ``Kernel`` global in a kernel as its dispatcher, and keeps the kernels'
    disk cache fresh across modules (``toptraj.compiled.cache``); once, on numba's import."""
    global _numba_taught
    if _numba_taught:
        return
    from numba.core import types
    from numba.core.typing.typeof import typeof_impl

    cache.keep_fresh()

    @typeof_impl.register(Kernel)
    def _typeof_kernel(value: Kernel, context: Any) -> Any:
        return types.Dispatcher(value.dispatcher)

    _numba_taught = True
