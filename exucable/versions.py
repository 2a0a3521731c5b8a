"""Versions of exucable and the packages that shape its results (recorded in every summary)."""

from __future__ import annotations

import platform
from importlib.metadata import PackageNotFoundError, version

from . import __version__

__all__ = ["versions", "version_line"]


def versions() -> dict[str, str]:
    """exucable's, Exudyn's, numpy's and Python's versions.

    Exudyn's is its installed distribution's, read without importing it (only ``model/`` and
    ``solve*`` import Exudyn; ``--version`` stays fast).
    """
    import numpy

    try:
        exudyn_version = version("exudyn")
    except PackageNotFoundError:
        exudyn_version = "not installed"
    return {"exucable": __version__, "exudyn": exudyn_version, "numpy": numpy.__version__,
            "python": platform.python_version()}


def version_line() -> str:
    """One line for ``exucable --version``: exucable's and Exudyn's versions."""
    v = versions()
    return f"exucable {v['exucable']} (Exudyn {v['exudyn']}, numpy {v['numpy']}, Python {v['python']})"
