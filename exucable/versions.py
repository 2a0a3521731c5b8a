"""Versions of exucable and the packages that shape its results (recorded in every summary)."""

from __future__ import annotations

import platform

from . import __version__

__all__ = ["versions", "version_line"]


def versions() -> dict[str, str]:
    """exucable's, Exudyn's, numpy's and Python's versions.

    Imports Exudyn, so it is called when a result is written or ``--version`` is asked for,
    never at import time.
    """
    import exudyn
    import numpy

    return {"exucable": __version__, "exudyn": exudyn.__version__, "numpy": numpy.__version__,
            "python": platform.python_version()}


def version_line() -> str:
    """One line for ``exucable --version``: exucable's and Exudyn's versions."""
    v = versions()
    return f"exucable {v['exucable']} (Exudyn {v['exudyn']}, numpy {v['numpy']}, Python {v['python']})"
