"""How the compiled contact kernels are made, cached and loaded, and what happens when they cannot be.

The kernels (:mod:`.fast`, the broad phase :mod:`.broadphase`, the steady-mode kernel :mod:`.steady`,
the trust gauge's nearest-sample search :mod:`.nearest`) are decorated with :func:`njit` from here,
not numba's: it records the function and its numba options and imports nothing. A call then goes

1. to the ahead-of-time compiled extension module (:mod:`.aot`, built by ``exucable compile``) when
   a valid one exists and the arguments have the types it was compiled for: numba is not imported
   at all, which saves its import and CPU-target initialisation (0.7 s, issue 15, fixed cost);
2. else to numba's JIT dispatcher, created on first use with ``cache=True``: the first call in a
   fresh environment compiles (tens of seconds for :mod:`.fast`), later processes load the machine
   code from disk (a tenth of a second). Numba would load a kernel's machine code even after a
   helper it inlined from another file changed; :func:`forget_stale_machine_code` compiles it
   again then.

Nothing here sets ``NUMBA_*`` options: a process that imports exucable keeps numba's configuration
as the user set it. Numba looks for a writable cache directory in this order
(``numba.core.caching``):

1. ``$NUMBA_CACHE_DIR`` if set;
2. ``__pycache__`` next to the source (``exucable/contact/__pycache__``: an editable install);
3. the user's cache directory (``~/.cache/numba`` on Linux), used when the installed package is
   read-only, e.g. in a system site-packages.

A directory counts only if numba can write a file into it: a read-only ``__pycache__`` is skipped
even if it holds a valid cache. When none is writable, ``njit(cache=True)`` would raise and make
exucable unusable; :func:`jit_cache_available` sees this beforehand and the kernel is then compiled
in memory in every process (correct, only slower to start), with one warning saying how to fix it.
The ahead-of-time module follows the same places (:func:`exucable.contact.aot.directories`).
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

from ..io import atomic_write_text
from .aot import exported, key as sources_key

__all__ = ["njit", "Kernel", "forget_stale_machine_code", "jit_cache_available"]


def jit_cache_available(func) -> bool:
    """Whether numba can cache functions defined in ``func``'s source file on disk.

    Warns and returns False when no cache directory is writable (checked once per source file).
    """
    filename = func.__code__.co_filename
    if filename not in _CACHE_BY_FILE:
        _CACHE_BY_FILE[filename] = _probe_cache(func)
    return _CACHE_BY_FILE[filename]


_CACHE_BY_FILE: dict[str, bool] = {}


def _probe_cache(func) -> bool:
    from numba.core.caching import FunctionCache

    try:
        FunctionCache(func)
    except RuntimeError as exc:  # numba: "cannot cache function ...: no locator available"
        warnings.warn(f"exucable: the contact kernel cannot be cached on disk ({exc}); it is compiled "
                      "in every process. Set NUMBA_CACHE_DIR to a writable directory to cache it.",
                      RuntimeWarning, stacklevel=4)
        return False
    return True


def forget_stale_machine_code(dispatcher, name: str) -> bool:
    """Empty ``dispatcher``'s on-disk cache if the kernel sources changed since it was written.

    Numba keys a cached function on its own source file's time stamp and its own bytecode only:
    machine code that inlined a function from another file (the steady kernel inlines
    :mod:`.fast`'s closest-point and contact-law helpers) is loaded unchanged after that other file
    changes, i.e. the old code runs. A marker file beside the cache holds the hash of all this
    package's sources (:func:`exucable.contact.aot.key`, which keys the ahead-of-time module too);
    a different or missing marker flushes the cache index, so the kernel is compiled again.
    Returns whether it flushed. A cache it cannot write is left alone (numba then compiles in memory).
    """
    cache = getattr(dispatcher, "_cache", None)
    path = getattr(cache, "cache_path", None)
    if path is None:
        return False
    marker = Path(path) / f"{name}.sources"
    current = sources_key()
    try:
        if marker.read_text() == current:
            return False
    except OSError:
        pass
    try:
        cache.flush()
        atomic_write_text(marker, current)
    except OSError:
        return False
    return True


class Kernel:
    """A numba-compiled function that imports numba only when it has to.

    Calling it runs the ahead-of-time compiled version (:mod:`.aot`) when one is loaded and accepts
    the arguments' types, else numba's JIT dispatcher (:attr:`dispatcher`). Inside other compiled
    functions it behaves as the dispatcher: numba's inliner reads :attr:`targetoptions` and
    :attr:`py_func`, its typing :attr:`_numba_type_`.
    """

    def __init__(self, py_func, options):
        functools.update_wrapper(self, py_func)
        self.py_func = py_func
        self.targetoptions = dict(options)
        self.name = f"{py_func.__module__.rsplit('.', 1)[-1]}.{py_func.__name__}"  # e.g. "fast._contact_kernel"
        self._dispatcher = None

    @property
    def dispatcher(self):
        """Numba's JIT dispatcher (imports numba; cached on disk where it can be), or the plain
        Python function when numba is missing."""
        if self._dispatcher is None:
            try:
                from numba import njit as numba_njit
            except ImportError:  # pragma: no cover - numba is a dependency
                self._dispatcher = self.py_func
            else:
                options = dict(self.targetoptions)
                options.setdefault("cache", jit_cache_available(self.py_func))
                self._dispatcher = numba_njit(**options)(self.py_func)
                if options["cache"]:
                    forget_stale_machine_code(self._dispatcher, self.name)
        return self._dispatcher

    @property
    def _numba_type_(self):
        return self.dispatcher._numba_type_

    def __call__(self, *args, **kwargs):
        compiled = exported(self.name) if not kwargs else None   # the exports take positional arguments
        if compiled is not None and compiled.accepts(args):
            return compiled.function(*args)
        return self.dispatcher(*args, **kwargs)

    def __repr__(self):
        return f"<exucable kernel {self.name}>"


def njit(func=None, **options):
    """``numba.njit`` with the same options, deferred: see :class:`Kernel`."""
    if func is not None:
        return Kernel(func, options)
    return lambda f: Kernel(f, options)
