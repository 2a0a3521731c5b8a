"""Where the compiled contact kernel is cached, and what happens when it cannot be.

Numba compiles the kernel once (tens of seconds for :mod:`.fast`) and, with ``cache=True``, keeps
the machine code on disk so that later processes only load it (a tenth of a second). The same holds
for the broad phase (:mod:`.broadphase`), the steady-mode kernel (:mod:`.steady`) and the trust
gauge's nearest-sample search (:mod:`.nearest`). Nothing here sets ``NUMBA_*`` options: a process
that imports exucable keeps numba's configuration as the user set it. Numba looks for a writable
cache directory in this order (``numba.core.caching``):

1. ``$NUMBA_CACHE_DIR`` if set;
2. ``__pycache__`` next to the source (``exucable/contact/__pycache__``: an editable install);
3. the user's cache directory (``~/.cache/numba`` on Linux), used when the installed package is
   read-only, e.g. in a system site-packages.

A directory counts only if numba can write a file into it: a read-only ``__pycache__`` is skipped
even if it holds a valid cache. When none is writable, ``njit(cache=True)`` would raise at import
and make exucable unusable; :func:`jit_cache_available` sees this beforehand and the kernel is then
compiled in memory in every process (correct, only slower to start), with one warning saying how
to fix it.
"""

from __future__ import annotations

import warnings

__all__ = ["jit_cache_available"]


def jit_cache_available(func) -> bool:
    """Whether numba can cache functions defined in ``func``'s source file on disk.

    Warns (once per call) and returns False when no cache directory is writable.
    """
    from numba.core.caching import FunctionCache

    try:
        FunctionCache(func)
    except RuntimeError as exc:  # numba: "cannot cache function ...: no locator available"
        warnings.warn(f"exucable: the contact kernel cannot be cached on disk ({exc}); it is compiled "
                      "in every process. Set NUMBA_CACHE_DIR to a writable directory to cache it.",
                      RuntimeWarning, stacklevel=2)
        return False
    return True
