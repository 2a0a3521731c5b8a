"""How the compiled contact kernels are made, cached and loaded, and what happens when they cannot be.

The kernels (:mod:`.fast`, the broad phase :mod:`.broadphase`, the steady-mode kernel :mod:`.steady`,
the parts those two share, :mod:`.kernel_parts`, the trust gauge's nearest-sample search
:mod:`.nearest`, the compiled ANCF cable element :mod:`.ancf_cable`; outside this package the result
files' number formatter :mod:`exucable.output.numbers_text`, which :func:`load_cached_kernels` leaves
to its first call) are decorated with :func:`njit` from here, not numba's: it records the function
and its numba options and imports nothing until the first call (``import exucable`` stays light).
A call goes to numba's JIT dispatcher, created on first use with ``cache=True``: the first call in a
fresh environment compiles (tens of seconds for :mod:`.fast`; ``exucable compile`` does it up front,
and :func:`kernels_to_compile` lets a command say so before a run), later processes load the machine
code from disk (a tenth of a second, plus numba's own start-up).
Numba would load a kernel's machine code even after a helper it inlined from another file changed;
:func:`forget_stale_machine_code` compiles it again then.

Why no ahead-of-time module: numba's ``pycc`` is deprecated, and keeping it took private patches of
numba and a hand-kept table of signatures, for about half a second per process
(``docs/decisions/0001-numba-cache-instead-of-pycc.md``).

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
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import sys
import warnings
from pathlib import Path

from ..io import atomic_write_text

__all__ = ["njit", "Kernel", "SLOW_TO_COMPILE", "forget_stale_machine_code", "jit_cache_available",
           "kernels_to_compile", "load_cached_kernels", "sources_key", "KERNEL_MODULES"]

# The modules of this package holding kernels (``load_cached_kernels``)
KERNEL_MODULES = ("fast", "steady", "broadphase", "nearest", "profiles", "cable_pairs", "ancf_cable")

# The kernels whose compilation takes long enough to announce (tens of seconds each; the others
# take about a second): the dynamic and the steady contact kernel, as "module.function".
SLOW_TO_COMPILE = ("fast._contact_kernel", "steady._steady_kernel")


def sources_key(sources: Path | None = None) -> str:
    """Hash of what a kernel's machine code depends on beyond its own file: the sources of every
    module of this package (``sources``, default this package's directory: the kernels and the helpers
    they inline) and the numpy, numba and llvmlite versions. Numba's own index adds the CPU."""
    h = hashlib.sha256()
    for path in sorted(Path(sources or Path(__file__).resolve().parent).glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    versions = [sys.version]
    for dist in ("numpy", "numba", "llvmlite"):
        # the modules' own versions (the same strings as their distributions'): whoever asks for a
        # kernel imports them anyway, and no metadata search runs on every call
        try:
            versions.append(importlib.import_module(dist).__version__)
        except ImportError:
            versions.append("-")
    h.update("\0".join(versions).encode())
    return h.hexdigest()[:24]


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
    machine code that inlined a function from another file (both contact kernels
    inline :mod:`.kernel_parts`' closest-point and contact-law helpers) is loaded unchanged after that
    other file changes, i.e. the old code runs. A marker file beside the cache holds the hash of all this
    package's sources (:func:`sources_key`);
    a different or missing marker flushes the cache index, so the kernel is compiled again.
    Returns whether it flushed. A cache it cannot write is left alone (numba then compiles in memory).
    """
    marker = _marker_path(dispatcher, f"{name}.sources")
    if marker is None:
        return False
    cache = dispatcher._cache
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

    Calling it runs numba's JIT dispatcher (:attr:`dispatcher`), made on the first call. Inside other compiled
    functions it behaves as the dispatcher: numba's inliner reads :attr:`targetoptions` and
    :attr:`py_func`, its typing :attr:`_numba_type_`.
    """

    def __init__(self, py_func, options):
        functools.update_wrapper(self, py_func)
        self.py_func = py_func
        self.targetoptions = dict(options)
        self.name = f"{py_func.__module__.rsplit('.', 1)[-1]}.{py_func.__name__}"  # e.g. "fast._contact_kernel"
        self._dispatcher = None
        self._note_compiled = False     # the first call's machine code is not yet marked as cached

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
                    self._note_compiled = not self.is_cached()
        return self._dispatcher

    @property
    def _numba_type_(self):
        return self.dispatcher._numba_type_

    def __call__(self, *args, **kwargs):
        dispatcher = self.dispatcher
        if self._note_compiled:          # the first call compiles and caches: say so beside the cache
            result = dispatcher(*args, **kwargs)
            self._note_compiled = False
            marker = _marker_path(dispatcher, f"{self.name}.compiled")
            if marker is not None:
                try:
                    atomic_write_text(marker, sources_key())
                except OSError:
                    pass
            return result
        return dispatcher(*args, **kwargs)

    def is_cached(self) -> bool | None:
        """Whether numba's disk cache holds machine code of this kernel for the current sources
        (True), holds none (False: the first call compiles), or cannot tell (None: no disk cache).
        Read from a marker written beside the cache after the first call; imports numba."""
        marker = _marker_path(self.dispatcher, f"{self.name}.compiled")
        if marker is None:
            return None
        try:
            return marker.read_text() == sources_key()
        except OSError:
            return False

    def __repr__(self):
        return f"<exucable kernel {self.name}>"


def _marker_path(dispatcher, name: str) -> Path | None:
    """``name`` in the directory of ``dispatcher``'s disk cache, or None without one."""
    path = getattr(getattr(dispatcher, "_cache", None), "cache_path", None)
    return None if path is None else Path(path) / name


def njit(func=None, **options):
    """``numba.njit`` with the same options, deferred: see :class:`Kernel`."""
    if func is not None:
        return Kernel(func, options)
    return lambda f: Kernel(f, options)


def kernels_to_compile(names=SLOW_TO_COMPILE) -> list[str] | None:
    """Those of the kernels ``names`` ("module.function" in this package) whose first call in this
    environment will compile them (numba's cache holds no machine code for the current sources):
    ``[]`` when all are cached, None when numba cannot tell. Imports numba; compiles nothing."""
    import importlib

    pending = []
    for name in names:
        module, function = name.split(".")
        cached = getattr(importlib.import_module(f"{__package__}.{module}"), function).is_cached()
        if cached is None:
            return None
        if not cached:
            pending.append(name)
    return pending


def load_cached_kernels(modules=KERNEL_MODULES) -> int:
    """Load the machine code of every kernel in ``modules`` that numba's disk cache holds for this
    CPU, without calling the kernels (so without running anything); returns the number of signatures
    loaded. A sweep's fork server does this once, so that its case processes start with the code in
    memory instead of each reading it from disk on first call (about 0.1 s CPU per case).

    Compiles nothing: a kernel without cached code is left to its first call. Reads numba's cache
    index, an internal of numba: where that fails, nothing is loaded (only start-up time is lost).
    """
    import importlib

    loaded = 0
    for module in modules:
        mod = importlib.import_module(f"{__package__}.{module}")
        for kernel in vars(mod).values():
            if not isinstance(kernel, Kernel) or kernel.is_cached() is not True:
                continue
            dispatcher = kernel.dispatcher
            try:
                index = dispatcher._cache._cache_file._load_index()
                magic = dispatcher.targetctx.codegen().magic_tuple()
                signatures = [key[0] for key in index if key[1] == magic]
            except Exception:  # numba's internals moved: nothing preloaded, nothing broken
                continue
            for signature in signatures:
                try:
                    dispatcher.compile(signature)     # found in the cache: loaded, not compiled
                    loaded += 1
                except Exception:
                    pass
    return loaded
