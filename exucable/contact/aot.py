"""Ahead-of-time compiled contact kernels: a run that loads them never imports numba.

Numba's import and CPU-target initialisation cost about 0.7 s in every process that runs a cached
JIT kernel (issue 15, fixed cost; docs/performance.md). :mod:`.aot_build` compiles every kernel a
run calls (:data:`KERNELS`) into one extension module with numba's ``pycc`` (a C compiler is
needed, once): each export is a thin wrapper calling the kernel's own numba dispatcher, so the
kernel keeps its own ``fastmath``/``error_model`` flags, and the machine code is the JIT path's for
this CPU (bit for bit the same results). Importing the module needs numpy only.

Where it lives: the same places as numba's cache (:mod:`.jitcache`), see :func:`directories`:
the first writable of ``$NUMBA_CACHE_DIR/exucable`` (if that variable is set),
``exucable/contact/__pycache__`` and ``~/.cache/exucable`` (``$XDG_CACHE_HOME``); looked for in the
same order, read-only places included (a module built into a read-only install is used). The file name carries :func:`key`, a
hash of this package's kernel sources and of the Python, numpy, numba and llvmlite versions and the
CPU: a module built for other sources or another machine is never found (stale = absent). Built by
``exucable compile`` (and ``python3 dev.py`` after installing), written atomically.

At run time (:func:`exported`, on a kernel's first call): a valid module is loaded and used for
every call whose arguments have the exact types it was compiled for; otherwise (no module, stale,
unloadable, other argument types, or ``EXUCABLE_KERNELS=jit`` in the environment) the call goes to
numba's JIT dispatcher as before, cached on disk. An unloadable module warns once; a missing one
is the normal state before ``exucable compile`` and is silent. Unlike the ``nogil`` dispatchers,
the exports hold the GIL while they run (pycc's wrappers do not release it); exucable runs one
case per process, so nothing waits on it.
"""

from __future__ import annotations

import hashlib
import os
import platform
import sys
import sysconfig
import warnings
from importlib import metadata
from pathlib import Path

import numpy as np

__all__ = ["KERNELS", "MODE_VARIABLE", "directories", "exported", "filename", "find", "key", "reset", "status"]

MODULE_NAME = "exucable_kernels"
MODE_VARIABLE = "EXUCABLE_KERNELS"   # "jit": never load the ahead-of-time module

# Every kernel called from Python in a run (dynamic and steady modes, post-processing, the trust
# gauge), with the argument types of its call sites: f/i = float64/int64 scalar, b = bool, f1..f3 /
# i1, i2 = C-contiguous writable float64/int64 array of that many dimensions. A call with other
# types goes to the JIT dispatcher (tests/test_aot.py checks that the JIT path sees no others).
# fast._max_finite is not here: nothing calls it.
KERNELS = {
    "fast._contact_kernel": "f1 f1 f1 f1 f1 f1 f1 f2 i2 f1 f2 i1 i1 f f f f i f f f f f b f1 f3 f3 f2 i1 f2 "
                            "i i b i1 f2 f2 i f f2 b f2",
    "fast._points_kernel": "f1 f1 f1 f1 f1 f1 f1 f1 f1 f1 f1 f f1 f2 i1 i1 f f f f i f f f f f f2 i1 i i b i1 "
                           "f2 f2 i f i1 f2 f2 f2 f1 f1 f1",
    "fast._search_kernel": "f1 f1 f1 f1 f1 f1 f2 i1 i1 f2 i2 i i",
    "steady._steady_kernel": "f1 f1 f1 f1 f1 f1 f1 f1 f1 f1 f f2 i2 f2 f1 f2 i1 i1 f f f f i f f f f f b f1 "
                             "f3 f2 f2 i1 f2 f2 i i b i1 f2 f2 i f",
    "profiles._profiles": "f2 i1 f2 f f2 f2 f1 f1 b i1 f2 f2 f1 f2 f1 i1 i1 f1 f2 f2 f2 f1",
    "broadphase._element_boxes": "f1 f1 f f2 f2",
    "broadphase._sweep_pairs": "f2 f2 f2 f2 i1 i1 i i1 i1 i1 i1",
    "broadphase._pairs_to_csr": "i i1 i1 i i i1 i1 i1 i1",
    "nearest._nearest": "f2 f2 i1 i1 f1 i1",
}

_SCALARS = {"f": (float, np.float64), "i": (int, np.int64), "b": (bool, np.bool_)}
_DTYPES = {"f": np.dtype(np.float64), "i": np.dtype(np.int64)}


class Compiled:
    """One exported kernel and the argument types it accepts."""

    def __init__(self, function, tokens: str):
        self.function = function
        kinds = tokens.split()
        self.n_args = len(kinds)
        self.arrays = tuple((k, _DTYPES[t[0]], int(t[1:])) for k, t in enumerate(kinds) if len(t) > 1)
        self.scalars = tuple((k, _SCALARS[t]) for k, t in enumerate(kinds) if len(t) == 1)

    def accepts(self, args) -> bool:
        """Whether ``args`` have exactly the compiled types (the exported code does not check:
        another dtype, rank or memory layout would be misread)."""
        if len(args) != self.n_args:
            return False
        for k, accepted in self.scalars:
            if type(args[k]) not in accepted:
                return False
        for k, dtype, ndim in self.arrays:
            a = args[k]
            # carray: C-contiguous, aligned and writeable; numpy's dtype objects of native float64
            # and int64 are singletons (another object of equal dtype only costs the JIT path)
            if type(a) is not np.ndarray or a.dtype is not dtype or a.ndim != ndim or not a.flags.carray:
                return False
        return True


def export_name(name: str) -> str:
    """The module attribute of kernel ``name`` ("fast._contact_kernel" -> "fast__contact_kernel")."""
    module, function = name.split(".")
    return f"{module}_{function}"


def directories() -> list[Path]:
    """Where the module is looked for, in order, and built (the first writable one): numba's
    cache rules (``numba.core.caching``, its locators), ``exucable`` standing for ``numba``."""
    override = os.environ.get("NUMBA_CACHE_DIR")
    user = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return ([Path(override) / "exucable"] if override else []) + [Path(__file__).resolve().parent / "__pycache__",
                                                                  user / "exucable"]


def key(sources: Path | None = None) -> str:
    """Hash of what the compiled code depends on: the sources of every module of this package
    (``sources``, default this package's directory: the kernels, the helpers they inline, this
    table), Python, numpy, numba, llvmlite, the CPU."""
    h = hashlib.sha256()
    for path in sorted(Path(sources or Path(__file__).resolve().parent).glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    versions = [sys.version, sys.implementation.cache_tag, platform.machine(), np.__version__]
    for dist in ("numba", "llvmlite"):
        try:
            versions.append(metadata.version(dist))
        except metadata.PackageNotFoundError:
            versions.append("-")
    h.update("\0".join(versions + [_cpu()]).encode())
    return h.hexdigest()[:24]


def _cpu() -> str:
    """The CPU model and instruction-set flags (the code is compiled for the host CPU)."""
    try:
        with open("/proc/cpuinfo") as f:
            lines = {}
            for line in f:
                name, _, value = line.partition(":")
                name = name.strip()
                if name in ("model name", "flags", "Features", "CPU part") and name not in lines:
                    lines[name] = value.strip()
                if not line.strip() and lines:
                    break
            return repr(sorted(lines.items()))
    except OSError:
        return platform.processor() + platform.platform()


def filename(module_key: str) -> str:
    return f"{MODULE_NAME}-{module_key}{sysconfig.get_config_var('EXT_SUFFIX')}"


def find() -> Path | None:
    """The valid module for the current sources and machine, if one was built."""
    name = filename(key())
    for directory in directories():
        if (directory / name).is_file():
            return directory / name
    return None


_loaded: dict = {}


def exported(name: str) -> Compiled | None:
    """Kernel ``name`` from the ahead-of-time module, or None (then use the JIT dispatcher).
    Looked up once per process (:func:`reset` looks again)."""
    if "exports" not in _loaded:
        _loaded["exports"] = _load()
    return _loaded["exports"].get(name)


def reset() -> None:
    """Forget the loaded module: the next kernel call reads ``EXUCABLE_KERNELS`` and the disk again."""
    _loaded.clear()


def _load() -> dict:
    if os.environ.get(MODE_VARIABLE, "").strip().lower() == "jit":
        return {}
    path = find()
    if path is None:
        return {}
    import importlib.util

    try:
        spec = importlib.util.spec_from_file_location(MODULE_NAME, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        functions = {name: getattr(module, export_name(name)) for name in KERNELS}
    except (ImportError, OSError, AttributeError) as exc:
        warnings.warn(f"exucable: the compiled kernels {path} cannot be loaded ({exc}); numba compiles "
                      "them instead. Rebuild with `exucable compile --force`.", RuntimeWarning, stacklevel=4)
        return {}
    return {name: Compiled(functions[name], tokens) for name, tokens in KERNELS.items()}


def status() -> dict:
    """Where the module is (or would be built) and whether it is valid."""
    path = find()
    return {"valid": path is not None, "path": path, "key": key(),
            "forced_jit": os.environ.get(MODE_VARIABLE, "").strip().lower() == "jit",
            "directories": directories()}
