"""Versions of exucable and the packages that shape its results (recorded in every summary)."""

from __future__ import annotations

import platform
import sys
from functools import lru_cache

from ..version import __version__

__all__ = ["versions", "version_line"]


def versions() -> dict[str, str]:
    """exucable's, Exudyn's, numpy's and Python's versions.

    Exudyn's is its installed distribution's, read without importing it (only ``model/`` and
    ``solve*`` import Exudyn; ``--version`` stays fast).
    """
    import numpy

    return {"exucable": __version__, "exudyn": _installed_version("exudyn"), "numpy": numpy.__version__,
            "python": platform.python_version()}


@lru_cache(maxsize=None)
def _installed_version(distribution: str) -> str:
    """An installed distribution's version, read once per process: the imported module's own
    ``__version__`` when a run has imported it (no metadata search), else its distribution's metadata
    (``--version``, which does not import Exudyn)."""
    module = sys.modules.get(distribution)
    if isinstance(getattr(module, "__version__", None), str):
        return module.__version__
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version(distribution)
    except PackageNotFoundError:
        return "not installed"


def version_line() -> str:
    """One line for ``exucable --version``: exucable's and Exudyn's versions."""
    v = versions()
    return f"exucable {v['exucable']} (Exudyn {v['exudyn']}, numpy {v['numpy']}, Python {v['python']})"
