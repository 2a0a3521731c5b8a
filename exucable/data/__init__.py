"""Files shipped with exucable as package data: the scenarios (``scenarios/``) and the reference
values with their sources (``reference/``).

In a source checkout both are the top-level directories of the repository (linked here); in an
installed wheel they are copies inside the package. Either way :func:`data_path` finds them through
:mod:`importlib.resources`, so ``exucable validate`` runs from any directory.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

__all__ = ["data_path"]


def data_path(*parts: str) -> Path:
    """The shipped file or directory ``parts`` (e.g. ``data_path("scenarios", "fast")``) as a path.

    Raises
    ------
    FileNotFoundError
        If it is not there (an incomplete installation), naming the path looked for.
    """
    path = Path(str(files(__name__).joinpath(*parts)))
    if not path.exists():
        raise FileNotFoundError(f"exucable's package data has no {'/'.join(parts)} (looked for {path}); "
                                "reinstall exucable")
    return path
