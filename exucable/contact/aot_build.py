"""Build the ahead-of-time compiled contact kernels (:mod:`.aot`: what, where, when used).

Imports numba (and its deprecated but working ``pycc``) only when :func:`build` runs.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import tempfile
import time
import warnings
from pathlib import Path

from ..io import atomic_write_bytes
from . import aot

__all__ = ["CompilerUnavailable", "build", "numba_argtypes"]

class CompilerUnavailable(RuntimeError):
    """No C compiler, no pycc or no writable directory: the kernels stay numba's JIT ones."""


def _writable(directory: Path) -> bool:
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            pass
    except OSError:
        return False
    return True


def build(directory: Path | None = None) -> tuple[Path, float]:
    """Compile :data:`~exucable.contact.aot.KERNELS` into the module for the current sources and machine.

    Writes it atomically to ``directory`` or the first writable of :func:`directories`, removes
    modules of older keys there, and returns (path, seconds). Imports numba; compiles (and caches)
    the JIT kernels first if they are not cached. Raises :class:`CompilerUnavailable` when no
    directory is writable or pycc or the C compiler fails, RuntimeError when a kernel does not
    compile for its row of the table.
    """
    t0 = time.perf_counter()
    candidates = [Path(directory)] if directory is not None else aot.directories()
    target = next((d for d in candidates if _writable(d)), None)
    if target is None:
        raise CompilerUnavailable("no writable directory for the compiled kernels among "
                                  f"{', '.join(map(str, candidates))}; set NUMBA_CACHE_DIR to a writable directory")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")          # pycc is deprecated (numba 0.68 ships it and it works)
            from numba.core import types
            from numba.pycc import CC
    except ImportError as exc:                       # a numba without pycc, a Python without distutils
        raise CompilerUnavailable(f"numba's pycc cannot be imported: {exc}") from exc
    module_key = aot.key()
    cc = CC(aot.MODULE_NAME)
    cc.target_cpu = "host"
    cc.verbose = False
    for name, tokens in aot.KERNELS.items():
        module, function = name.split(".")
        dispatcher = getattr(importlib.import_module(f"{__package__}.{module}"), function).dispatcher  # the table names them
        argtypes = numba_argtypes(tokens, types)
        try:
            dispatcher.compile(argtypes)
        except Exception as exc:
            raise RuntimeError(f"{name} does not compile for the argument types of exucable/contact/aot.py's "
                               f"KERNELS table ({tokens!r}); update the table to its call sites: {exc}") from exc
        returns = dispatcher.overloads[argtypes].signature.return_type
        cc.export(aot.export_name(name), returns(*argtypes))(_call_through(dispatcher, len(argtypes)))
    with tempfile.TemporaryDirectory(prefix="exucable-kernels-") as tmp:
        cc.output_dir = tmp
        cc.output_file = aot.filename(module_key)
        try:
            with warnings.catch_warnings(), _machine_code_as_the_jit():
                warnings.simplefilter("ignore")
                cc.compile()
        except Exception as exc:   # distutils/setuptools report a missing compiler in several ways
            raise CompilerUnavailable(f"compiling the kernels failed: {exc}") from exc
        built = Path(tmp) / aot.filename(module_key)
        path = atomic_write_bytes(target / built.name, built.read_bytes())
        os.chmod(path, 0o755)            # as the compiler left it (the temporary file was private)
    for old in target.glob(f"{aot.MODULE_NAME}-*"):
        if old.name != aot.filename(module_key):
            old.unlink(missing_ok=True)
    aot.reset()
    return path, time.perf_counter() - t0


@contextlib.contextmanager
def _machine_code_as_the_jit():
    """Make pycc emit the JIT's machine code for each kernel, so that both paths give the same
    numbers bit for bit (tests/test_aot.py).

    pycc links each kernel's optimised LLVM module (the very IR the JIT turns into machine code)
    into the module of the exports, then by default optimises the whole again and generates code
    for the named CPU without its feature list. With ``fastmath`` reassociation, that second
    optimisation regroups sums (measured: results differ in the last bits, up to 1e-15 relative).
    Here the second pass is skipped (the exports are one call each, nothing to gain) and the
    host's features are given, as numba's JIT does (``numba.core.codegen.JITCPUCodegen``).
    """
    from numba.core import codegen

    saved = codegen.AOTCPUCodegen._customize_tm_features, codegen.AOTCodeLibrary._optimize_final_module
    codegen.AOTCPUCodegen._customize_tm_features = lambda self: self._get_host_cpu_features()
    codegen.AOTCodeLibrary._optimize_final_module = lambda self: None
    try:
        yield
    finally:
        codegen.AOTCPUCodegen._customize_tm_features, codegen.AOTCodeLibrary._optimize_final_module = saved


def numba_argtypes(tokens: str, types) -> tuple:
    """The numba argument types of a :data:`KERNELS` entry (``types``: ``numba.core.types``)."""
    array = {"f": types.float64, "i": types.int64}
    scalar = {"f": types.float64, "i": types.int64, "b": types.boolean}
    return tuple(scalar[t] if len(t) == 1 else types.Array(array[t[0]], int(t[1:]), "C") for t in tokens.split())


def _call_through(dispatcher, n_args: int):
    """``def wrapper(a0, ..., an): return dispatcher(a0, ..., an)``: pycc exports a Python function of
    fixed arity, compiled by numba, whose call to the dispatcher compiles the kernel with the
    kernel's own flags."""
    names = ", ".join(f"a{i}" for i in range(n_args))
    scope = {"kernel": dispatcher}
    exec(f"def wrapper({names}):\n    return kernel({names})\n", scope)  # noqa: S102 - fixed template
    return scope["wrapper"]
